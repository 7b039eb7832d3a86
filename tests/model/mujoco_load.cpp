// mujoco_load FILE [SECONDS]: loads an MJCF or URDF file with MuJoCo (Debian's libmujoco-dev), the
// way a MuJoCo user would, and prints what MuJoCo made of it; then, from the keyframe `home` if the
// file has one, simulates SECONDS (default 1) with no control torque and checks that the state
// stays finite and MuJoCo raised no warning. Exit status 1 if MuJoCo refuses the file or the
// simulation fails. A test tool (tests/model/CheckMuJoCoLoads.cmake), never installed.
#include <mujoco/mujoco.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: mujoco_load FILE [SECONDS]\n");
    return 2;
  }
  const double seconds = argc == 3 ? std::atof(argv[2]) : 1.0;
  char error[1000] = "";
  mjModel* m = mj_loadXML(argv[1], nullptr, error, sizeof error);
  if (m == nullptr) {
    std::printf("MuJoCo refuses %s: %s\n", argv[1], error);
    return 1;
  }
  double mass = 0;
  for (int b = 0; b < m->nbody; ++b) mass += m->body_mass[b];
  std::printf("MuJoCo loads %s: nq=%d nv=%d nbody=%d nu=%d mass=%.6g kg\n", argv[1], m->nq, m->nv, m->nbody, m->nu, mass);
  mjData* d = mj_makeData(m);
  if (m->nkey > 0) mj_resetDataKeyframe(m, d, 0);
  const int steps = static_cast<int>(seconds / m->opt.timestep);
  bool finite = true;
  for (int s = 0; s < steps && finite; ++s) {
    mj_step(m, d);
    for (int i = 0; i < m->nv; ++i) finite = finite && std::isfinite(d->qpos[i]) && std::isfinite(d->qvel[i]);
  }
  int warnings = 0;
  for (int w = 0; w < mjNWARNING; ++w) warnings += d->warning[w].number;
  std::printf("after %d steps of %g s: %s, %d MuJoCo warnings, q =", steps, m->opt.timestep,
              finite ? "finite" : "NOT FINITE", warnings);
  for (int i = 0; i < m->nq; ++i) std::printf(" %.4f", d->qpos[i]);
  std::printf("\n");
  mj_deleteData(d);
  mj_deleteModel(m);
  return finite && warnings == 0 ? 0 : 1;
}
