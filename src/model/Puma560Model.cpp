// Puma 560 parameters. Source: Peter Corke's Robotics Toolbox, Python models/DH/Puma560.py link
// table (lines 92-179) and MATLAB models/mdl_puma560.m (lines 80-141), as collected in
// shared/refdata/01_puma560_model_params.txt.
#include "rp/model/Puma560Model.hpp"

#include <numbers>

namespace rp {

namespace {

constexpr double kDeg = std::numbers::pi / 180;

Matrix<3, 3> diagonal(double xx, double yy, double zz) {
  Matrix<3, 3> m;
  m(0, 0) = xx;
  m(1, 1) = yy;
  m(2, 2) = zz;
  return m;
}

Vector<3> vec(double x, double y, double z) {
  Vector<3> v;
  v = x, y, z;
  return v;
}

std::vector<LinkParameters> pumaLinks(double d1) {
  const double pi = std::numbers::pi;
  struct Row {
    double d, a, alpha, m;
    Vector<3> r;
    Matrix<3, 3> I;
    double Jm, G, B, TcP, TcN, qmin, qmax;
  };
  const Row rows[6] = {
      {d1, 0, pi / 2, 0, vec(0, 0, 0), diagonal(0, 0.35, 0), 200e-6, -62.6111, 1.48e-3, 0.395, -0.435, -160, 160},
      {0, 0.4318, 0, 17.4, vec(-0.3638, 0.006, 0.2275), diagonal(0.13, 0.524, 0.539), 200e-6, 107.815, 0.817e-3,
       0.126, -0.071, -110, 110},
      {0.15005, 0.0203, -pi / 2, 4.8, vec(-0.0203, -0.0141, 0.070), diagonal(0.066, 0.086, 0.0125), 200e-6, -53.7063,
       1.38e-3, 0.132, -0.105, -135, 135},
      {0.4318, 0, pi / 2, 0.82, vec(0, 0.019, 0), diagonal(1.8e-3, 1.3e-3, 1.8e-3), 33e-6, 76.0364, 71.2e-6, 11.2e-3,
       -16.9e-3, -266, 266},
      {0, 0, -pi / 2, 0.34, vec(0, 0, 0), diagonal(0.3e-3, 0.4e-3, 0.3e-3), 33e-6, 71.923, 82.6e-6, 9.26e-3, -14.5e-3,
       -100, 100},
      {0, 0, 0, 0.09, vec(0, 0, 0.032), diagonal(0.15e-3, 0.15e-3, 0.04e-3), 33e-6, 76.686, 36.7e-6, 3.96e-3, -10.5e-3,
       -266, 266},
  };
  // Assumed drive limits (not part of the toolbox model): joint speed [rad/s], torque [N m].
  const double vmax[6] = {2.0, 2.0, 2.5, 4.0, 4.0, 4.0};
  const double taumax[6] = {100, 200, 100, 25, 25, 25};
  const double amax[6] = {4, 4, 5, 8, 8, 8};
  std::vector<LinkParameters> links(6);
  for (int i = 0; i < 6; ++i) {
    LinkParameters& l = links[static_cast<std::size_t>(i)];
    const Row& r = rows[i];
    l.d = r.d;
    l.a = r.a;
    l.alpha = r.alpha;
    l.mass = r.m;
    l.com = r.r;
    l.inertia = r.I;
    l.motorInertia = r.Jm;
    l.gearRatio = r.G;
    l.viscousFriction = r.B;
    l.coulombFrictionPositive = r.TcP;
    l.coulombFrictionNegative = r.TcN;
    l.positionMin = r.qmin * kDeg;
    l.positionMax = r.qmax * kDeg;
    l.velocityLimit = vmax[i];
    l.accelerationLimit = amax[i];
    l.jerkLimit = 10 * amax[i];
    l.torqueLimit = taumax[i];
  }
  return links;
}

}  // namespace

Puma560Model::Puma560Model(double pedestalHeight, const Transform& base, const Transform& tool)
    : ManipulatorModel("puma560", pumaLinks(pedestalHeight), base, tool) {
  JointVector qr(6);
  qr = 0, std::numbers::pi / 2, -std::numbers::pi / 2, 0, 0, 0;  // the toolbox's ready pose
  setHomePosition(qr);
}

}  // namespace rp
