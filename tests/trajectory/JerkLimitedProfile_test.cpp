// The jerk-limited rest-to-rest profile: durations derived by hand for each case, and seeded
// random property tests (limits, continuity, exact end, and the bang-bang structure of a
// time-optimal motion: at every instant the jerk, the acceleration or the velocity is at a limit).
#include "rp/trajectory/JerkLimitedProfile.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rp {
namespace {

TEST(JerkLimitedProfile, DurationsOfTheThreeCasesDerivedByHand) {
  // Velocity limit reached: 2 s to reach 1 m/s (1 m), 2 s to stop (1 m), 8 m cruising: 12 s.
  EXPECT_NEAR(JerkLimitedProfile(10, 1, 1, 1).getDuration(), 12.0, 1e-12);
  // Acceleration limit reached, velocity not: jerk phases of 1 s around a constant-acceleration
  // phase; with T_a the acceleration phase, D = a (T_a - 1) T_a = 3 gives T_a = (1 + sqrt(13)) / 2.
  EXPECT_NEAR(JerkLimitedProfile(3, 10, 1, 1).getDuration(), 1 + std::sqrt(13.0), 1e-12);
  // Neither: four jerk phases of t_j with D = 2 j t_j^3 = 1, so t_j = 2^(-1/3) and T = 4 t_j.
  EXPECT_NEAR(JerkLimitedProfile(1, 1, 1, 1).getDuration(), 4 * std::cbrt(0.5), 1e-12);
  // Velocity reached without reaching the acceleration limit: t_j = sqrt(v / j) = 0.5 s, the
  // speed-up takes 1 s and covers 0.125 m; D = 1: cruise (1 - 0.25) / 0.25 = 3 s; T = 5 s.
  EXPECT_NEAR(JerkLimitedProfile(1, 0.25, 10, 1).getDuration(), 5.0, 1e-12);
  EXPECT_EQ(JerkLimitedProfile(0, 1, 1, 1).getDuration(), 0.0);
  EXPECT_THROW(JerkLimitedProfile(-1, 1, 1, 1), std::invalid_argument);
  EXPECT_THROW(JerkLimitedProfile(1, 0, 1, 1), std::invalid_argument);
}

TEST(JerkLimitedProfile, RandomProfilesRespectLimitsAndAreTimeOptimal) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  const int count = 2000;  // the sanitizers slow every evaluation down
#else
  const int count = 20000;
#endif
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> logu(-2, 2);
  for (int k = 0; k < count; ++k) {
    const double D = std::pow(10.0, logu(rng)), v = std::pow(10.0, logu(rng)), a = std::pow(10.0, logu(rng)),
                 j = std::pow(10.0, logu(rng));
    const JerkLimitedProfile p(D, v, a, j);
    const double T = p.getDuration();
    ASSERT_GT(T, 0);
    const int samples = 400;
    const double dt = T / samples;
    ProfileState prev = p.evaluate(0);
    EXPECT_EQ(prev.position, 0);
    EXPECT_EQ(prev.velocity, 0);
    EXPECT_EQ(prev.acceleration, 0);
    for (int i = 1; i <= samples; ++i) {
      const double t = i == samples ? T : i * dt;
      const ProfileState s = p.evaluate(t);
      ASSERT_LE(std::abs(s.velocity), v * (1 + 1e-9)) << "D=" << D << " v=" << v << " a=" << a << " j=" << j;
      ASSERT_LE(std::abs(s.acceleration), a * (1 + 1e-9));
      // Continuity and the jerk limit: the acceleration changes at most j dt per step, the
      // velocity by at most a dt, the position by at most v dt.
      ASSERT_LE(std::abs(s.acceleration - prev.acceleration), j * dt * (1 + 1e-6) + 1e-12);
      ASSERT_LE(std::abs(s.velocity - prev.velocity), a * dt * (1 + 1e-6) + 1e-12);
      ASSERT_LE(std::abs(s.position - prev.position), v * dt * (1 + 1e-6) + 1e-12);
      // Bang-bang structure (Pontryagin): at every instant the jerk is at its limit, or the
      // acceleration is (constant-acceleration phase), or the velocity (cruise). The jerk is
      // estimated by a central difference over a window far shorter than any phase.
      const double h = T * 1e-7;
      const double left = std::abs(s.acceleration - p.evaluate(t - h).acceleration) / h;
      const double right = t + h <= T ? std::abs(p.evaluate(t + h).acceleration - s.acceleration) / h : left;
      // On either side of t (a phase switch may fall exactly on a sample).
      const bool atJerk = std::abs(left - j) < 1e-4 * j || std::abs(right - j) < 1e-4 * j;
      const bool atAcc = std::abs(std::abs(s.acceleration) - a) < 1e-9 * a;
      const bool atVel = std::abs(std::abs(s.velocity) - v) < 1e-9 * v;
      ASSERT_TRUE(atJerk || atAcc || atVel || i == samples)
          << "t=" << t << " of " << T << " jerk " << left << "/" << right << " a " << s.acceleration << " v "
          << s.velocity;
      prev = s;
    }
    EXPECT_NEAR(prev.position, D, 1e-9 * D);
    EXPECT_NEAR(prev.velocity, 0, 1e-9 * v);
    EXPECT_NEAR(prev.acceleration, 0, 1e-9 * a);
  }
}

}  // namespace
}  // namespace rp
