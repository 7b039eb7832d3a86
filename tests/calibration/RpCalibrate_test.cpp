// rp-calibrate as a user runs it, against simulated arms whose plant was perturbed by known
// amounts through rp.cfg (simEncoderOffset, simFrictionScale, simMassScale, simPayload), on the
// simulated clock: the exit status, the JSON it prints checked against the perturbations, the
// settings it writes, and bad arguments (exit 2, one line on stderr naming the argument).
//
// Tolerances. The simulated plant has no torque noise; what the fit cannot explain is the
// integration error of the simulation, the encoders' quantisation (simCountsPerRadian 1e5: 1e-5
// rad) and, for a plant whose masses differ, the model's inertial and Coriolis torques.
//
// The integration error that matters is the friction's: each 1 ms step integrates the smooth
// dynamics by RK4, viscous friction included, and applies the Coulomb friction after it as an
// impulse. Within a step at constant speed the joints therefore speed up by h M^-1 (F_c + F_v v)
// before the impulse takes it back, and the viscous friction, taken at those velocities, is too
// large by up to E_i = (h/2) F_v,i sum_j |M^-1_ij| (F_c,j + F_v,j v_max) (about 0.03 N m on the
// Puma's joint 1: 5.8 N m s/rad, 26 N m, 3 kg m^2). It has the sign of the velocity, so it goes
// into the Coulomb friction and asymmetry (bound E_i) and, through the speeds' spread 0.1-0.8
// rad/s, the viscous friction (bound 3 E_i); integrationBound() computes E_i from the plant.
//
// The rest shows in the fit's residual (about 3e-3 N m rms). Such an error is systematic, not random, so the standard errors (which assume white
// noise) do not bound it; Cauchy-Schwarz does: an unmodelled torque e moves parameter k by at most
// |e| sqrt([(A^T A)^-1]_kk), which the program reports as each estimate's "resolution" (sqrt(N)
// standard errors, |e| taken as sqrt(N) times the residual's rms). Each check below requires the
// error to be within 2 resolutions (the factor for the part of e that the fit absorbs and the
// residual does not show) and within a fixed bound stated at the check, so that a wrong
// resolution cannot hide a wrong value.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "Calibration.hpp"
#include "RunProgram.hpp"
#include "ScratchDirectory.hpp"
#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/model/Model.hpp"

namespace rp::calibration {
namespace {

using test::Outcome;
using test::slurp;

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "rp_calibrate_" + std::to_string(::getpid()) + "_" + name; }

Outcome run(const std::string& args, const std::string& config = "") {
  const std::string base = tempPath("run");
  std::string command = std::string("'") + RP_CALIBRATE_PROGRAM + "' -simclock";
  if (!config.empty()) {
    std::ofstream(base + ".cfg") << config;
    command += " -config " + base + ".cfg";
  }
  Outcome r = test::runProgram(command + " " + args, base);
  std::remove((base + ".cfg").c_str());
  return r;
}

constexpr double kDeg = M_PI / 180;

// Checks one estimate against the truth: within 2 resolutions plus `integration` (the simulation's
// integration error's share) and within `bound`.
void expectRecovered(const nlohmann::json& e, double truth, double bound, const std::string& what,
                     double integration = 0) {
  const double value = e.at("value").get<double>(), resolution = e.at("resolution").get<double>();
  EXPECT_LE(std::abs(value - truth), 2 * resolution + integration)
      << what << ": " << value << " vs " << truth << " (resolution " << resolution << ", integration error bound "
      << integration << ")";
  EXPECT_LE(std::abs(value - truth), bound) << what << ": " << value << " vs " << truth;
}

// E_i above for the plant `plant` (largest over random poses), servo period h = 1 ms, v_max 0.8 rad/s.
JointVector integrationBound(const ManipulatorModel& plant) {
  const int n = plant.getNumberOfJoints();
  constexpr double h = 1e-3, vmax = 0.8;
  ManipulatorData data(plant);
  JointVector fv(n), f(n), bound = JointVector::Zero(n);
  for (int j = 0; j < n; ++j) {
    double viscous = 0, coulomb = 0, asymmetry = 0;
    modelFriction(plant, j, viscous, coulomb, asymmetry);
    fv(j) = viscous;
    f(j) = coulomb + std::abs(asymmetry) + viscous * vmax;
  }
  std::mt19937 rng(1);
  for (int s = 0; s < 100; ++s) {
    JointVector q(n);
    for (int j = 0; j < n; ++j)
      q(j) = std::uniform_real_distribution<double>(std::max(plant.getPositionMin()(j), -M_PI),
                                                    std::min(plant.getPositionMax()(j), M_PI))(rng);
    const Eigen::MatrixXd Minv = Eigen::MatrixXd(massMatrix(plant, data, q, true)).inverse();
    const Eigen::VectorXd e = (h / 2) * fv.cwiseProduct(Minv.cwiseAbs() * f);
    bound = bound.cwiseMax(JointVector(e));
  }
  return bound;
}

TEST(RpCalibrate, RecoversThePumasEncoderOffsetsAndFriction) {
  const double offsetDeg[6] = {0.3, 0.3, -0.25, 0.4, 0.3, 0.2};
  const double friction[6] = {1, 1.3, 0.8, 1.2, 1, 1};
  const std::string config =
      "[puma]\nclass Puma560\n"
      "simEncoderOffset 0.3 0.3 -0.25 0.4 0.3 0.2\n"
      "simFrictionScale 1 1.3 0.8 1.2 1 1\n"
      "simCountsPerRadian 100000\n";
  const test::ScratchFile writtenFile("rp_calibrate_" + std::to_string(::getpid()) + "_written.cfg");  // removed at the end
  const Outcome r = run("--json --write " + writtenFile.path(), config);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  EXPECT_EQ(out.at("arm"), "puma");
  // The torques paired with the state in the middle of the servo step they acted over, less the
  // inertial torque of the step's mean acceleration, leave 2.7e-3 N m rms (the integration error
  // above); paired with the state at the step's start and no inertial torque they left 7.7e-3.
  EXPECT_LT(out.at("residualRms").get<double>(), 0.005) << "N m";
  const auto& offsets = out.at("offsets");
  // A vertical first joint turns nothing against gravity; the last link's centre of mass lies on
  // the last joint's axis: neither offset is observable, and both are reported so, left at 0.
  EXPECT_FALSE(offsets.at(0).at("observable").get<bool>());
  EXPECT_FALSE(offsets.at(5).at("observable").get<bool>());
  EXPECT_EQ(offsets.at(0).at("value").get<double>(), 0);
  // Joints 2 and 3 carry the arm: within 0.01 degrees.
  for (int j = 1; j < 3; ++j) {
    const auto& o = offsets.at(static_cast<std::size_t>(j));
    ASSERT_TRUE(o.at("observable").get<bool>()) << "joint " << j + 1;
    expectRecovered(o, offsetDeg[j] * kDeg, 0.01 * kDeg, "offset of joint " + std::to_string(j + 1));
  }
  // Joints 4 and 5 turn only the wrist's small moments (0.005-0.01 N m/rad of gravity torque): the
  // residual leaves them unresolved by degrees, and the program says so; no setting is written.
  for (int j = 3; j < 5; ++j) {
    const auto& o = offsets.at(static_cast<std::size_t>(j));
    EXPECT_LT(o.at("sensitivity").get<double>(), 0.05) << "joint " << j + 1;
    EXPECT_GT(o.at("resolution").get<double>(), 1 * kDeg) << "joint " << j + 1;
  }
  Puma560Model puma;
  PlantDeviations d;
  d.frictionScale = JointVector(6);
  d.frictionScale << 1, 1.3, 0.8, 1.2, 1, 1;
  const ManipulatorSimulation plant(puma, d);
  const JointVector E = integrationBound(plant.getModel());
  for (int j = 0; j < 6; ++j) {
    double fv = 0, fc = 0, fa = 0;
    modelFriction(puma, j, fv, fc, fa);
    const auto& f = out.at("friction").at(static_cast<std::size_t>(j));
    const std::string joint = "joint " + std::to_string(j + 1);
    // And within 3 % (viscous, asymmetry) and 1 % (Coulomb) of the true value.
    expectRecovered(f.at("viscous"), friction[j] * fv, 0.03 * friction[j] * fv, joint + " viscous", 3 * E(j));
    expectRecovered(f.at("coulomb"), friction[j] * fc, 0.01 * friction[j] * fc, joint + " Coulomb", E(j));
    expectRecovered(f.at("asymmetry"), friction[j] * fa, 0.03 * friction[j] * fc, joint + " asymmetry", E(j));
  }
  // The masses were not perturbed: the base gravity parameters are the model's.
  for (const auto& b : out.at("gravity").at("base"))
    expectRecovered(b, b.at("nominal").get<double>(), 0.02, b.at("expression").get<std::string>());
  // What rp.cfg can take of it, and the reasons for the rest.
  const std::string written = slurp(writtenFile.path());
  EXPECT_NE(written.find("[puma]\nclass Puma560\n"), std::string::npos) << written;
  EXPECT_NE(written.find("simFrictionScale 1"), std::string::npos) << written;
  EXPECT_NE(written.find("simEncoderOffset 0 0.3"), std::string::npos) << written;
  EXPECT_NE(written.find(" 0 0 0   # deg"), std::string::npos) << "joints 4-6 not written: " << written;
  EXPECT_NE(written.find("joint 1: not observable from gravity"), std::string::npos) << written;
  EXPECT_NE(written.find("joint 4: poorly observable"), std::string::npos) << written;
  EXPECT_NE(written.find("no setting"), std::string::npos) << written;
}

TEST(RpCalibrate, RecoversThePumasGravityParametersAfterAMassChange) {
  PlantDeviations d;
  d.massScale = JointVector(6);
  d.massScale << 1, 1.25, 0.85, 1, 1, 1;
  d.payload = 1.5;
  d.frictionScale = JointVector::Constant(6, 0.7);
  const std::string config =
      "[puma]\nclass Puma560\n"
      "simMassScale 1 1.25 0.85 1 1 1\n"
      "simPayload 1.5\n"
      "simFrictionScale 0.7\n"
      "simCountsPerRadian 100000\n";
  const Outcome r = run("puma --offsets off --json", config);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  EXPECT_FALSE(out.at("offsetsFitted").get<bool>());
  Puma560Model puma;
  const ManipulatorSimulation plant(puma, d);
  const BaseParameters bp = findBaseParameters(puma);
  const Eigen::VectorXd truth = bp.project(gravityParameters(plant.getModel()));
  const auto& base = out.at("gravity").at("base");
  ASSERT_EQ(base.size(), bp.base.size());
  double largestChange = 0;
  for (std::size_t b = 0; b < bp.base.size(); ++b) {
    ASSERT_EQ(base.at(b).at("name"), gravityParameterName(bp.base[b]));
    const double t = truth(static_cast<Eigen::Index>(b));
    largestChange = std::max(largestChange, std::abs(t - base.at(b).at("nominal").get<double>()));
    expectRecovered(base.at(b), t, 0.02, bp.expression(static_cast<int>(b)));
  }
  EXPECT_GT(largestChange, 0.5) << "the perturbation moves some base parameter by far more than the tolerance";
  const JointVector E = integrationBound(plant.getModel());
  for (int j = 0; j < 6; ++j) {
    double fv = 0, fc = 0, fa = 0;
    modelFriction(puma, j, fv, fc, fa);
    expectRecovered(out.at("friction").at(static_cast<std::size_t>(j)).at("coulomb"), 0.7 * fc, 0.01 * 0.7 * fc,
                    "Coulomb friction of joint " + std::to_string(j + 1), E(j));
  }
  // Link 1's parameters never act on a gravity torque.
  const auto& unidentifiable = out.at("gravity").at("unidentifiable");
  for (const char* name : {"m1", "mcx1", "mcy1", "mcz1"})
    EXPECT_NE(std::find(unidentifiable.begin(), unidentifiable.end(), name), unidentifiable.end()) << name;
}

// A WAM 7 (no friction in its model): the offsets of joints 2-4 within 0.005 degrees; those of
// the wrist are reported as poorly observable, joint 1's as not observable; the gravity
// parameters are the model's.
TEST(RpCalibrate, RecoversTheWam7sEncoderOffsets) {
  const double offsetDeg[7] = {0.3, -0.3, 0.25, 0.4, -0.3, 0.3, 0.2};
  const Outcome r = run("--json",
                        "[wam]\nclass WAM\nlinks 7\nsimEncoderOffset 0.3 -0.3 0.25 0.4 -0.3 0.3 0.2\n"
                        "simCountsPerRadian 100000\n");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json out = nlohmann::json::parse(r.out);
  const auto& offsets = out.at("offsets");
  EXPECT_FALSE(offsets.at(0).at("observable").get<bool>()) << "a vertical first joint";
  for (int j = 1; j < 4; ++j)
    expectRecovered(offsets.at(static_cast<std::size_t>(j)), offsetDeg[j] * kDeg, 0.005 * kDeg,
                    "offset of joint " + std::to_string(j + 1));
  for (int j = 4; j < 7; ++j)
    EXPECT_GT(offsets.at(static_cast<std::size_t>(j)).at("resolution").get<double>(), 0.1 * kDeg)
        << "joint " << j + 1 << ": the wrist's small moments leave its offset poorly observable";
  for (const auto& b : out.at("gravity").at("base"))
    expectRecovered(b, b.at("nominal").get<double>(), 1e-3, b.at("expression").get<std::string>());
}

TEST(RpCalibrate, PrintsATableByDefault) {
  const Outcome r = run("--poses 4 --sweep-speeds 0.3,0.8", "[arm]\nclass Puma560\nsimEncoderOffset 0 0.5 0 0 0 0\n");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("rp-calibrate: arm (Puma560, 6 joints)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("      1  not observable"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not identifiable (no effect on the gravity torque): m1 mcx1 mcy1 mcz1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rp.cfg: the controller's model has no setting for encoder offsets, friction or gravity"),
            std::string::npos) << r.out;
}

TEST(RpCalibrate, BadArgumentsExitWith2AndNameTheArgument) {
  const struct {
    const char* args;
    const char* message;
  } cases[] = {
      {"--poses 0", "rp-calibrate: --poses: '0' is not an integer in 1..1000\n"},
      {"--poses", "rp-calibrate: --poses needs a value\n"},
      {"--offsets maybe", "rp-calibrate: --offsets: 'maybe' is not on or off\n"},
      {"--sweep-speeds 0.1,x", "rp-calibrate: --sweep-speeds: 'x' is not a positive number\n"},
      {"--pass-speed -1", "rp-calibrate: --pass-speed: '-1' is not a positive number\n"},
      {"--pass-speed 1e-5", "rp-calibrate: --pass-speed: '1e-5' is below the least speed, 0.01 rad/s\n"},
      {"--sweep-speeds 0.1,0.001", "rp-calibrate: --sweep-speeds: '0.001' is below the least speed, 0.01 rad/s\n"},
      {"--frobnicate", "rp-calibrate: unknown option --frobnicate\n"},
      {"--json --json2", "rp-calibrate: unknown option --json2\n"},
      {"--seed 1 --seed 2", "rp-calibrate: --seed is given twice\n"},
      {"puma other", "rp-calibrate: unexpected argument 'other' (NAME is 'puma')\n"},
  };
  for (const auto& c : cases) {
    const Outcome r = run(c.args);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_EQ(r.out, "") << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
  }
  const Outcome missing = run("nosuch", "[puma]\nclass Puma560\n");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("nosuch"), std::string::npos) << missing.err;
  const Outcome help = run("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("--sweep-speeds"), std::string::npos) << help.out;
}

}  // namespace
}  // namespace rp::calibration
