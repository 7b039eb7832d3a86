// The calling thread's ManipulatorData for the servo cycle's algorithms (ThreadWorkspace.hpp).
#include "ThreadWorkspace.hpp"

#include <new>
#include <type_traits>

namespace rp::internal {

namespace {

// Raw storage and the object made in it. Trivially destructible, so the thread-local needs no
// exit handler (registering one allocates); the object made in it owns no heap memory (it is
// never made for a model with mimic joints, whose data would own its chain's), so it needs no
// destruction either.
struct Workspace {
  alignas(ManipulatorData) unsigned char bytes[sizeof(ManipulatorData)];
  ManipulatorData* data = nullptr;
};
static_assert(std::is_trivially_destructible_v<Workspace>);

thread_local Workspace tWorkspace;

}  // namespace

ManipulatorData* threadWorkspace(const ManipulatorModel& model) noexcept {
  if (model.hasMimicJoints()) return nullptr;
  Workspace& w = tWorkspace;
  if (w.data != nullptr && w.data->n == model.getNumberOfJoints()) return w.data;
  if (w.data != nullptr) w.data->~ManipulatorData();
  w.data = new (w.bytes) ManipulatorData(model);  // no allocation without mimic joints
  return w.data;
}

}  // namespace rp::internal
