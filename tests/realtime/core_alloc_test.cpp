// What a servo cycle may call on its object: error status, shutdown request, state snapshots.
#include <gtest/gtest.h>

#include "AllocationCounter.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/rt/TripleBuffer.hpp"

namespace rp {
namespace {

TEST(CoreRealtime, ErrorStatusShutdownRequestAndSnapshotsDoNotAllocate) {
  ObjectManager::resetShutdown();
  PhysicalObject object("servo");
  TripleBuffer<StateSnapshot> snapshots;
  StateSnapshot s;
  s.size = 3;
  int code = 0;
  bool simulated = object.isSimulationModeOn();  // first use creates the platform settings
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 1000; ++i) {
      s.cycle = static_cast<std::uint64_t>(i);
      s.values[0] = i;
      snapshots.write(s);
      object.setError(i % 5, "joint 3 exceeds its torque limit of 50 N m");
      code += object.getErrorCode();
      simulated = object.isSimulationModeOn() || simulated;
    }
    object.requestSystemShutdown("torque limit exceeded");
    ObjectManager::requestSystemShutdown("a second request");
    EXPECT_EQ(guard.count(), 0u);
  }
  EXPECT_GT(code, 0);
  EXPECT_TRUE(simulated);
  ASSERT_TRUE(ObjectManager::waitForShutdown(60));
  EXPECT_EQ(ObjectManager::getShutdownReason(), "torque limit exceeded");
  StateSnapshot out;
  ASSERT_TRUE(snapshots.read(out));
  EXPECT_EQ(out.cycle, 999u);
  ObjectManager::resetShutdown();
}

}  // namespace
}  // namespace rp
