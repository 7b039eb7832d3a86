// The Barrett arm under the paper's name (rp/manipulator/BarrettArm.hpp).
#include "rp/manipulator/BarrettArm.hpp"

#include "rp/core/TypeDatabase.hpp"

namespace rp {

BarrettArm::BarrettArm(const std::string& name, int links)
    : WAM(ClassSection(name, "BarrettArm"), links, DerivedClass{}) {
  startControlLoop();  // last: the loop never sees a half-built object
}

BarrettArm::~BarrettArm() { stopControlLoop(); }

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::BarrettArm, "BarrettArm");
