#include "TestClasses.hpp"

#include "rp/core/TypeDatabase.hpp"

// Each class registers itself with one line next to its definition (the library's classes, such as
// Puma560 and WAM, in their own .cpp files).
RP_REGISTER_CLASS_AS(rp::test::TestArm, "TestArm");
RP_REGISTER_CLASS_AS(rp::test::TestFunction, "TestFunction");
RP_REGISTER_CLASS_AS(rp::test::SlowShutdown, "SlowShutdown");
