#include "rp/effector/WorkPiece.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "rp/core/ClassSection.hpp"
#include "rp/core/Configuration.hpp"
#include "rp/core/TypeDatabase.hpp"
#include "rp/math/Transform.hpp"
#include "rp/rt/ControlProgram.hpp"

namespace rp {

struct WorkPiece::Impl {
  mutable std::mutex mutex;
  double mass = 0.5;                          // [kg]
  Vector<3> size = Vector<3>::Constant(0.04);  // [m]
  double tableHeight = 0;                      // [m]
  std::unique_ptr<Fall> fall;                  // the last fall (its loop ends by itself)
  FallState state;                             // its last step
};

// The free fall: a control loop on the platform's clock that moves the piece down from where it
// was let go, z0 - g/2 (t - t0)^2, until it lies on the table, then ends.
class WorkPiece::Fall : public ControlProgram {
 public:
  Fall(WorkPiece& piece, const Transform& from, double restZ)
      : ControlProgram(piece.getName() + ".fall"), piece_(piece), from_(from), restZ_(restZ) {
    setLogWriter(nullptr);  // nothing to log
  }
  ~Fall() override { stop(); }  // before this part of the object is gone
  Fall(const Fall&) = delete;
  Fall& operator=(const Fall&) = delete;
  // Whether the loop has ended (landed, or stopped by a system shutdown); isRunning() stays true
  // until the thread is joined.
  bool hasEnded() const { return ended_.load(std::memory_order_acquire); }

 protected:
  void control() override {
    const double t = getTime();
    if (t0_ < 0) t0_ = t;
    const double dt = t - t0_;
    Transform pose = from_;
    const double z = from_(2, 3) - 0.5 * kGravity * dt * dt;
    pose(2, 3) = std::max(z, restZ_);
    piece_.setTransform(pose);
    {
      std::lock_guard<std::mutex> lock(piece_.impl_->mutex);
      FallState& s = piece_.impl_->state;
      s.time = dt;
      s.height = pose(2, 3);
      s.from = from_(2, 3);
      s.landed = z <= restZ_;
      ++s.steps;
    }
    if (z <= restZ_) requestStop();  // on the table
  }
  void exitControl() override { ended_.store(true, std::memory_order_release); }

 private:
  WorkPiece& piece_;
  Transform from_;
  double restZ_;
  double t0_ = -1;
  std::atomic<bool> ended_{false};
};

WorkPiece::WorkPiece(const std::string& name)
    : PhysicalObject(ClassSection(name, "WorkPiece")), impl_(std::make_unique<Impl>()) {
  if (const ConfigSection* section = configSection()) {
    if (const ConfigSetting* s = section->find("mass")) {
      const double kg = section->getNumbers("mass").at(0);
      if (!(kg > 0)) throw section->errorAt(*s, "setting 'mass' must be positive");
      impl_->mass = kg;
    }
    if (const ConfigSetting* s = section->find("size")) {
      const std::vector<double> mm = section->getNumbers("size");
      for (std::size_t i = 0; i < 3; ++i) {
        if (!(mm.at(i) > 0)) throw section->errorAt(*s, "setting 'size' must have three positive edge lengths");
        impl_->size(static_cast<int>(i)) = mm[i] / 1000.0;
      }
    }
    if (section->has("tableHeight")) impl_->tableHeight = section->getNumbers("tableHeight").at(0) / 1000.0;
  }
  publishObject();  // complete: other threads (the Scene Viewer) may use it
}

WorkPiece::~WorkPiece() {
  withdrawObject();  // first: other threads keep off from here on
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->fall.reset();  // stops a fall under way
}

void WorkPiece::declareSettings(SettingSchema& schema) {
  PhysicalObject::declareSettings(schema);
  schema.addNumbers("mass", 1, "kg", "mass of the work piece", 0, std::numeric_limits<double>::max());
  schema.addNumbers("size", 3, "mm", "edge lengths of the work piece (x, y, z)", 0, std::numeric_limits<double>::max());
  schema.addNumbers("tableHeight", 1, "mm", "height of the table the work piece falls onto");
  schema.setDefault("mass", "0.5");
  schema.setDefault("size", "40 40 40");
  schema.setDefault("tableHeight", "0");
}

void WorkPiece::setMass(double kg) {
  if (!(kg > 0) || !std::isfinite(kg)) throw std::invalid_argument(getName() + ": the mass must be positive and finite");
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->mass = kg;
}

double WorkPiece::getMass() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->mass;
}

void WorkPiece::setSize(const Vector<3>& meters) {
  if (!meters.allFinite() || !(meters.minCoeff() > 0))
    throw std::invalid_argument(getName() + ": the edge lengths must be positive and finite");
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->size = meters;
}

Vector<3> WorkPiece::getSize() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->size;
}

void WorkPiece::setTableHeight(double meters) {
  if (!std::isfinite(meters)) throw std::invalid_argument(getName() + ": the table height must be finite");
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->tableHeight = meters;
}

double WorkPiece::getTableHeight() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->tableHeight;
}

double WorkPiece::restingHeight(const Transform& pose) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  // Half the extent along z of the box in this orientation.
  double half = 0;
  for (int i = 0; i < 3; ++i) half += 0.5 * std::abs(pose(2, i)) * impl_->size(i);
  return impl_->tableHeight + half;
}

Model3D WorkPiece::get3DModel() const {
  Model3D m;
  Shape box;
  box.kind = ShapeKind::Box;
  box.size = getSize();
  box.color = Color{0.85, 0.45, 0.1, 1.0};
  m.shapes.push_back(box);
  return m;
}

void WorkPiece::attachTo(PhysicalObject& holder) {
  std::unique_ptr<Fall> fall;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    fall = std::move(impl_->fall);
  }
  fall.reset();  // stops a fall under way (outside the lock: its loop sets the pose)
  const Transform world = getWorldTransform();
  setConnection(holder, "base");
  setTransform(rigidInverse(holder.getWorldTransform()) * world);  // stays where it is, now moving with it
}

void WorkPiece::release() {
  const Transform world = getWorldTransform();
  clearConnection();
  setTransform(world);  // let go where it is
  auto fall = std::make_unique<Fall>(*this, world, restingHeight(world));
  std::unique_ptr<Fall> previous;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    previous = std::move(impl_->fall);
  }
  previous.reset();
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->state = FallState{};
  impl_->fall = std::move(fall);
  impl_->fall->start();
}

bool WorkPiece::isFalling() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->fall != nullptr && !impl_->fall->hasEnded();
}

WorkPiece::FallState WorkPiece::getFallState() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->state;
}

bool WorkPiece::waitUntilLanded(double timeoutSeconds) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutSeconds);
  while (isFalling()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return true;
}

}  // namespace rp

RP_REGISTER_CLASS_AS(rp::WorkPiece, "WorkPiece");
