// Virtual walls: the paper's Figure 22, a custom servo control.
//
// A virtual wall is the plane w . (x, 1) = 0 with w = (n, d0): the end-effector is outside the
// wall where w . x > 0 and inside where it is < 0, and inside it feels a spring force along the
// normal n that pushes it back out. Gravity compensation is on, so outside the wall the arm floats
// and can be pushed around.
//
// Run: build/bin/virtual_walls [--duration S] [--push FX,FY,FZ]
//   --duration S   stop after S seconds of robot time (default: run until Ctrl-C)
//   --push F       in simulation, push the end-effector with the constant force F [N] (world
//                  frame), to feel the wall without a GUI; the final position is printed at exit
//
// Changes from the paper's Figure 22:
// 1. `int main(int argc, char* argv[])`; the end of main waits for Ctrl-C or --duration (the
//    paper's main returned at once, which would destroy the robot) and handles --push.
// 2. `getJointPositon` is spelled `getJointPosition`.
// 3. The size bug: the force uses the first three wall coefficients, the normal n, instead of
//    the 4-vector (`d_wallCoefficients.getSubMatrix<3, 1>(1, 1)`).
// 4. The sign: the paper's `distance * n * kf` points into the wall (distance < 0 inside); the
//    force here is `-distance * n * kf`, which pushes the end-effector back out.
// 5. The numbers: the paper's wall (0, 0, -1, 3) lies 3 m up, out of the Puma's reach, and
//    kf = 0.01 N/m is too soft to feel. Here the wall is the plane x = 0.4 m, (-1, 0, 0, 0.4),
//    with kf = 2000 N/m (a 20 N push goes 1 cm into the wall).
// 6. `override` on calculate() and `std::` where needed; the class is unchanged otherwise.
// 7. The wall is drawn in the Scene Viewer: a `Wall` object, a thin box on the plane, on the side
//    the arm must stay out of (not in the paper).
// 8. At the end the DefaultPositionControl holds the arm where the push left it (not in the
//    paper): floating, it drifted on into a joint stop while the program ended.
#include "RoboticPlatform.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>

// ----- Create a new servo control class -----

template <int numJoints>
class VirtualWallServoControl : public ServoControl  // (1)
{
 public:
  void calculate() override {
    // What is the distance of the end-effector to the wall?
    Transform t = d_manipulator->getEndEffectorPosition();
    double distance = dotProduct(d_wallCoefficients, t.getColumn(4));
    if (distance > 0)  // No control output
      return;

    // We are inside the wall. Generate reacting force
    Vector<3> force = -distance * d_wallCoefficients.getSubMatrix<3, 1>(1, 1) * d_kf;

    // Convert to joint torque
    Vector<numJoints> pos = d_manipulator->getJointPosition();
    Vector<numJoints> torque;
    d_manipulator->endEffectorForceToJointTorque(pos, force, torque);

    // Do the control output
    d_manipulator->setControlOutput(torque);
  }

  Vector<4> d_wallCoefficients;
  double d_kf;
};

// ----- The wall, as the Scene Viewer draws it (7) -----

class Wall : public PhysicalObject {
 public:
  // The plane n . x + d0 = 0, drawn as a box `thickness` deep behind it (where
  // n . x + d0 < 0), `width` by `height` about the point of the plane nearest to (0, 0, 1 m).
  Wall(const std::string& name, const Vector<4>& w, double width = 1.6, double height = 1.6, double thickness = 0.02)
      : PhysicalObject(name), w_(w), size_{{thickness}, {width}, {height}} {
    publishObject();  // complete: the Scene Viewer may draw it
  }
  ~Wall() override { withdrawObject(); }
  Model3D get3DModel() const override {
    const Vector<3> normal = w_.getSubMatrix<3, 1>(1, 1);
    const Vector<3> n = normal / normal.norm();
    const Vector<3> up{{0.0}, {0.0}, {1.0}};
    const Vector<3> onPlane = up - ((dotProduct(normal, up) + w_(3)) / normal.norm()) * n;  // nearest to (0, 0, 1)
    Shape box;
    box.kind = ShapeKind::Box;
    // The box's x axis along -n (into the wall), its centre half a thickness behind the plane.
    const Vector<3> x = -n;
    const Vector<3> y = std::abs(x(2)) < 0.9 ? Vector<3>(crossProduct(up, x)) : Vector<3>{{0.0}, {1.0}, {0.0}};
    const Vector<3> z = crossProduct(x, y);
    Matrix<3, 3> r;
    for (int i = 0; i < 3; ++i) r(i, 0) = x(i), r(i, 1) = y(i) / y.norm(), r(i, 2) = z(i) / z.norm();
    box.pose = makeTransform(r, onPlane + 0.5 * size_(0) * x);
    box.size = size_;
    box.color = Color{0.55, 0.75, 0.95, 1.0};
    Model3D m;
    m.shapes.push_back(box);
    return m;
  }

 private:
  Vector<4> w_;
  Vector<3> size_;
};

// ----- Use the virtual walls servo control -----

int main(int argc, char* argv[]) {
  RoboticPlatform::init(argc, argv,
                        "  --duration S     stop after S seconds of robot time\n"
                        "  --push FX,FY,FZ  push the simulated end-effector with a constant force [N]\n");

  double duration = -1;
  Vector<6> push;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--duration" && i + 1 < argc) {
      duration = std::atof(argv[++i]);
    } else if (a == "--push" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%lf,%lf,%lf", &push(0), &push(1), &push(2)) != 3) {
        std::cerr << "virtual_walls: --push needs FX,FY,FZ" << std::endl;
        return 2;
      }
    } else {
      std::cerr << "virtual_walls: unknown argument '" << a << "' (see --help)" << std::endl;
      return 2;
    }
  }

  Puma560 puma;  // Create the robot object

  // Virtual wall control for 6 joints
  VirtualWallServoControl<6> wallControl;  // (2)
  wallControl.d_kf = 2000;
  wallControl.d_wallCoefficients = -1, 0, 0, 0.4;
  Wall wall("wall", wallControl.d_wallCoefficients);  // (7)

  puma.setGravityCompensationOn();  // (3)
  puma.setServoControl(wallControl);

  // On the simulated clock, hold time still while the push starts, so runs are repeatable.
  auto* simClock = dynamic_cast<SimulatedClock*>(&puma.getClock());
  if (simClock != nullptr && duration >= 0) simClock->pause();
  if (push.squaredNorm() > 0) puma.applyExternalWrench(push);
  // Run until Ctrl-C (a system shutdown) or for `duration` seconds of robot time: whole servo
  // cycles, stopping a simulated clock (-simclock) exactly there.
  if (duration >= 0) {
    puma.runCycles(static_cast<std::uint64_t>(duration / puma.getPeriod() + 0.5));
  } else {
    while (!ObjectManager::isShutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const Transform t = puma.getEndEffectorTransform();
  std::cout << "final end-effector position: " << t(0, 3) << " " << t(1, 3) << " " << t(2, 3) << std::endl;
  puma.clearExternalWrench();
  // The push has set the arm moving, and floating under gravity compensation it would drift on
  // into a joint stop while the program ends: the DefaultPositionControl takes over and holds it
  // where it is (clearTrajectoryGenerator() asks for the hold), and after a run of --duration the
  // arm gets half a second of robot time to come to rest before the program ends.
  if (!ObjectManager::isShutdownRequested()) {
    puma.clearTrajectoryGenerator();
    puma.setServoControl(puma.getDefaultPositionControl());
    if (duration >= 0) puma.runCycles(static_cast<std::uint64_t>(0.5 / puma.getPeriod() + 0.5));
  }
  if (simClock != nullptr) simClock->resume();
  if (ObjectManager::isShutdownRequested()) {  // a fault, an emergency stop or Ctrl-C ended the motion
    std::cerr << "virtual_walls: stopped by a system shutdown: " << ObjectManager::getShutdownReason() << std::endl;
    return RoboticPlatform::kExitAfterShutdown;
  }
  return puma.getErrorCode() == 0 ? 0 : 1;
}
