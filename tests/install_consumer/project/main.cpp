// Written as the paper's programs are: one header, the platform's names unqualified.
#include "RoboticPlatform.hpp"

#include <iostream>

int main() {
  Transform base = translation(0.5, 0, 1);
  Transform link = zRotation(M_PI / 2) * translation(0.25, 0, 0);
  Transform endEffector = base * link;
  Vector<4> tip = endEffector.getColumn(4);
  Vector<3> p;
  p = tip(0), tip(1), tip(2);
  RowVector<3> row = p.transpose();
  std::cout << "consumer: end-effector position " << row << std::endl;
  return 0;
}
