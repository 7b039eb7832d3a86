// The calling thread's ManipulatorData for the servo cycle's algorithms (ThreadWorkspace.hpp).
#include "ThreadWorkspace.hpp"

#include <type_traits>

#include "../rt/ThreadLocalSlot.hpp"

namespace rp::internal {

namespace {

// The object made in it owns no heap memory (it is never made for a model with mimic joints, whose
// data would own its chain's), so it needs no destruction at thread exit.
thread_local ThreadLocalSlot<ManipulatorData> tWorkspace;
static_assert(std::is_trivially_destructible_v<ThreadLocalSlot<ManipulatorData>>);

}  // namespace

ManipulatorData* threadWorkspace(const ManipulatorModel& model) noexcept {
  if (model.hasMimicJoints()) return nullptr;
  ThreadLocalSlot<ManipulatorData>& w = tWorkspace;
  if (ManipulatorData* data = w.get(); data != nullptr && data->n == model.getNumberOfJoints()) return data;
  return &w.make(model);  // no allocation without mimic joints
}

}  // namespace rp::internal
