// Barrett WAM parameters. Sources (see shared/refdata/05_barrett_wam_params.txt): libbarrett
// master 109faf6 config/wam7w.conf (kinematics l.22-41, dynamics l.43-107), config/wam4.conf
// (l.19-77), config/autotension.conf (joint stops), calibration_data zerocal.conf (home), WAM Arm
// User's Manual D1001 AH.00 Table 6 (joint limits); btclient WAM7.conf (gear ratios N).
#include "rp/model/WAMModel.hpp"

#include <numbers>

namespace rp {

namespace {

Matrix<3, 3> sym(double xx, double xy, double xz, double yy, double yz, double zz) {
  return Matrix<3, 3>{{xx, xy, xz}, {xy, yy, yz}, {xz, yz, zz}};
}

Vector<3> vec(double x, double y, double z) {
  Vector<3> v;
  v = x, y, z;
  return v;
}

std::vector<LinkParameters> wamLinks(int dof) {
  const double pi = std::numbers::pi;
  struct Row {
    double alpha, a, d, m;
    Vector<3> com;
    Matrix<3, 3> I;
    double qmin, qmax, G, taumax;
  };
  const Row link4of7 = {pi / 2, -0.045, 0, 2.17266212, vec(0.00553408, 0.00006822, 0.11927695),
                        sym(0.01067491, 0.00004503, -0.00135557, 0.01058659, -0.00011002, 0.00282036),
                        -0.9, 3.1, 18.0, 15};
  const Row link4of4 = {pi / 2, -0.045, 0, 1.0651, vec(10.95e-3, -0.03e-3, 140.54e-3),
                        sym(18485.77e-6, 2.19e-6, -1608.68e-6, 18916.58e-6, 5.15e-6, 1975.17e-6),
                        -0.9, 3.1, 18.0, 15};
  const Row rows[7] = {
      {-pi / 2, 0, 0, 10.7677, vec(-4.43e-3, 121.89e-3, -0.66e-3),
       sym(134880.33e-6, -2130.41e-6, -124.85e-6, 113283.69e-6, 685.55e-6, 90463.30e-6), -2.6, 2.6, 42.0, 25},
      {pi / 2, 0, 0, 3.8749, vec(-2.37e-3, 31.06e-3, 15.42e-3),
       sym(21409.58e-6, 271.72e-6, 24.61e-6, 13778.75e-6, -1819.20e-6, 15589.06e-6), -2.0, 2.0, 28.25, 20},
      {-pi / 2, 0.045, 0.55, 1.8023, vec(-38.26e-3, 207.51e-3, 0.03e-3),
       sym(59110.77e-6, -2496.12e-6, 7.38e-6, 3245.50e-6, -17.67e-6, 59270.43e-6), -2.8, 2.8, 28.25, 15},
      dof == 7 ? link4of7 : link4of4,
      {-pi / 2, 0, 0.3, 0.35655692, vec(0.00005483, 0.02886286, 0.00148493),
       sym(0.00037112, -0.00000008, -0.00000003, 0.00019434, -0.00001613, 0.00038209), -4.76, 1.24, 10.27, 5},
      {pi / 2, 0, 0, 0.40915886, vec(-0.00005923, -0.01686123, 0.02419052),
       sym(0.00054889, 0.00000019, -0.00000010, 0.00023846, -0.00004430, 0.00045133), -1.6, 1.6, 10.27, 5},
      {0, 0, 0.0609, 0.07548270, vec(0.00014836, 0.00007252, -0.00335185),
       sym(0.00003911, 0.00000019, 0, 0.00003877, 0, 0.00007614), -3.0, 3.0, 14.93, 5},
  };
  std::vector<LinkParameters> links(static_cast<std::size_t>(dof));
  for (int i = 0; i < dof; ++i) {
    LinkParameters& l = links[static_cast<std::size_t>(i)];
    const Row& r = rows[i];
    l.alpha = r.alpha;
    l.a = r.a;
    l.d = r.d;
    l.mass = r.m;
    l.com = r.com;
    l.inertia = r.I;
    l.gearRatio = r.G;
    l.positionMin = r.qmin;
    l.positionMax = r.qmax;
    l.velocityLimit = 2.0;  // assumed
    l.accelerationLimit = 6.0;
    l.jerkLimit = 60.0;
    l.torqueLimit = r.taumax;
  }
  return links;
}

}  // namespace

WAM7Model::WAM7Model(const Transform& base, const Transform& tool) : ManipulatorModel("wam7", wamLinks(7), base, tool) {
  JointVector home(7);
  // zerocal.conf's home (0, -2, 0, 3.13, 0, 0, 0) rests on the joint-2 and joint-4 stops; the
  // model's home is 0.05 rad inside them so that a simulated arm starts within its limits.
  home = 0, -1.95, 0, 3.05, 0, 0, 0;
  setHomePosition(home);
}

WAM4Model::WAM4Model(const Transform& base, const Transform& tool) : ManipulatorModel("wam4", wamLinks(4), base, tool) {
  JointVector home(4);
  home = 0, -1.95, 0, 3.05;  // inside the stops, as for WAM7Model
  setHomePosition(home);
}

}  // namespace rp
