#pragma once
// MuJoCo (Debian's libmujoco-dev) as an independent reference in the export tests: a model loaded
// from MJCF or URDF text, and its mass matrix and bias forces at a state.
#include <gtest/gtest.h>

#include <mujoco/mujoco.h>

#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <string>

#include "rp/model/ManipulatorModel.hpp"

namespace rp::test {

// A MuJoCo model and data. MuJoCo 2.2 reads models from files only (or a virtual file system),
// so the text goes through a temporary file; `extension` (.xml or .urdf) picks the parser.
class MuJoCoModel {
 public:
  MuJoCoModel(const std::string& text, const std::string& extension) {
    const std::string file =
        testing::TempDir() + "/rp_mujoco_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++) + extension;
    std::ofstream(file) << text;
    char error[1000] = "";
    m = mj_loadXML(file.c_str(), nullptr, error, sizeof error);
    std::remove(file.c_str());
    if (m == nullptr) throw std::runtime_error(std::string("MuJoCo cannot load the model: ") + error);
    d = mj_makeData(m);
  }
  ~MuJoCoModel() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
  MuJoCoModel(const MuJoCoModel&) = delete;
  MuJoCoModel& operator=(const MuJoCoModel&) = delete;

  // Runs MuJoCo's forward pass at (q, qd) (all joints, in order).
  void forward(const JointVector& q, const JointVector& qd) {
    for (int i = 0; i < m->nq; ++i) d->qpos[i] = q(i);
    for (int i = 0; i < m->nv; ++i) d->qvel[i] = qd(i);
    mj_forward(m, d);
  }
  // The dense mass matrix of the last forward() (with armature).
  JointMatrix massMatrix() const {
    std::vector<mjtNum> dense(static_cast<std::size_t>(m->nv * m->nv));
    mj_fullM(m, dense.data(), d->qM);
    JointMatrix M(m->nv, m->nv);
    for (int r = 0; r < m->nv; ++r)
      for (int c = 0; c < m->nv; ++c) M(r, c) = dense[static_cast<std::size_t>(r * m->nv + c)];
    return M;
  }
  // Bias forces C(q, qd) qd + g(q) of the last forward().
  JointVector bias() const { return vector(d->qfrc_bias); }
  // Passive forces (damping) of the last forward().
  JointVector passive() const { return vector(d->qfrc_passive); }

  mjModel* m = nullptr;
  mjData* d = nullptr;

 private:
  static int& counter() {
    static int n = 0;
    return n;
  }
  JointVector vector(const mjtNum* v) const {
    JointVector x(m->nv);
    for (int i = 0; i < m->nv; ++i) x(i) = v[i];
    return x;
  }
};

// Largest element of |a - b| over the largest element of |b| (a relative error).
template <typename A, typename B>
double relativeError(const A& a, const B& b) {
  const double scale = b.cwiseAbs().maxCoeff();
  return (a - b).cwiseAbs().maxCoeff() / (scale > 0 ? scale : 1.0);
}

}  // namespace rp::test
