// Property test of the queue: 100,000 seeded random multi-segment joint sequences (random
// limits, random via points, half of them with blends of random size), evaluated the way the
// servo loop does (1 kHz). Every setpoint stays within the limits; consecutive setpoints differ by
// at most what the limits allow over one cycle (position, velocity and acceleration are
// continuous across segment and blend boundaries: an acceleration jump would exceed jerk * dt);
// each sequence ends at rest exactly on its last target; an unblended sequence lasts exactly the
// sum of the analytic time-optimal durations (joints synchronised in time, the default: each
// motion lasts as long as its slowest joint alone), a blended one no longer.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "rp/RoboticPlatform.hpp"

namespace rp {
namespace {

TEST(TrajectoryProperty, RandomSequencesWithAndWithoutBlends) {
  RoboticPlatform::setConfiguration(Configuration());
  RoboticPlatform::setSimulationModeOn();
  RoboticPlatform::useSimulatedClock();
  ObjectManager::resetShutdown();
  Puma560 puma;
  SimulatedClock& clock = dynamic_cast<SimulatedClock&>(RoboticPlatform::getDefaultClock());
  clock.pause();  // the test evaluates the setpoints itself
  while (puma.getCycleCount() < 1) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const ManipulatorModel& model = puma.getModel();
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  const int sequences = 1000;
#else
  const int sequences = 100000;
#endif
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> unit(0, 1);
  const double dt = 1e-3;
  // Every sequence has its own generator and starts at t = 10 s: small absolute times keep the
  // rounding of t (and so of the acceleration differences) far below the 1e-9 relative tolerance.
  const double time = 10;
  long segments = 0, blends = 0, samples = 0, vias = 0, slower = 0;
  double blendedTime = 0, unblendedTime = 0;  // of the blended sequences
  for (int s = 0; s < sequences; ++s) {
    DefaultTrajectoryGenerator<6> tragen;
    tragen.setSpeedFraction(1);
    JointVector vmax(6), amax(6), jmax(6);
    for (int i = 0; i < 6; ++i) {
      vmax(i) = 1 + 5 * unit(rng);
      amax(i) = 5 + 35 * unit(rng);
      jmax(i) = 50 + 750 * unit(rng);
    }
    tragen.setJointLimits(vmax, amax, jmax);
    const bool blended = s % 2 == 1;
    tragen.setJointBlendRadius(blended ? 0.05 + unit(rng) : 0.0);
    puma.setTrajectoryGenerator(tragen);
    // Disconnects the generator before it is destroyed, also when an assertion returns early
    // (a connected generator's destructor waits for its queue to finish).
    struct Detach {
      Puma560& arm;
      ~Detach() { arm.clearTrajectoryGenerator(); }
    } detach{puma};
    const int count = 2 + static_cast<int>(rng() % 4);
    JointVector from = tragen.getLastTarget(), last;
    double analytic = 0;
    for (int k = 0; k < count; ++k) {
      JointVector q(6);
      for (int i = 0; i < 6; ++i) {
        q(i) = model.getPositionMin()(i) + (0.05 + 0.9 * unit(rng)) * (model.getPositionMax()(i) - model.getPositionMin()(i));
      }
      tragen.moveRadians(q);
      // The analytic duration of the time-synchronised rest-to-rest motion from `from` to `q`
      // (the default, Synchronization::Time): the slowest joint's own minimum time.
      double slowest = 0;
      for (int i = 0; i < 6; ++i) {
        slowest = std::max(slowest, JerkLimitedProfile(std::abs(q(i) - from(i)), vmax(i), amax(i), jmax(i)).getDuration());
      }
      analytic += slowest;
      from = last = q;
      ++segments;
    }
    blends += tragen.getBlendCount();
    if (blended) vias += count - 1;
    else EXPECT_EQ(tragen.getBlendCount(), 0);
    Setpoint sp, prev;
    sp.position = sp.velocity = sp.acceleration = JointVector(6);
    prev = sp;
    ASSERT_TRUE(tragen.getCurrentSetpoint(time, prev));
    double t = time;
    for (long k = 1; !tragen.isDone(); ++k) {
      t = time + static_cast<double>(k) * dt;
      ++samples;
      ASSERT_TRUE(tragen.getCurrentSetpoint(t, sp));
      for (int i = 0; i < 6; ++i) {
        ASSERT_LE(std::abs(sp.velocity(i)), vmax(i) * (1 + 1e-9)) << "sequence " << s << " joint " << i;
        ASSERT_LE(std::abs(sp.acceleration(i)), amax(i) * (1 + 1e-9)) << "sequence " << s << " joint " << i;
        ASSERT_LE(std::abs(sp.acceleration(i) - prev.acceleration(i)), jmax(i) * dt * (1 + 1e-9) + 1e-12)
            << "sequence " << s << " joint " << i << " at " << t - time;
        ASSERT_LE(std::abs(sp.velocity(i) - prev.velocity(i)), amax(i) * dt * (1 + 1e-9) + 1e-12)
            << "sequence " << s << " joint " << i;
        ASSERT_LE(std::abs(sp.position(i) - prev.position(i)), vmax(i) * dt * (1 + 1e-9) + 1e-12)
            << "sequence " << s << " joint " << i;
      }
      prev = sp;
      ASSERT_LT(t - time, 1000.0);
    }
    if (blended) {
      // A blend replaces the motion from the exit point to the entry point through the via point
      // at rest (at most half of each neighbouring segment) with an overlap, which is shorter, or
      // a quintic at most three times as long: so never more than three times the unblended time.
      EXPECT_LE(t - time, 3 * analytic + dt) << "sequence " << s;
      blendedTime += t - time;
      unblendedTime += analytic;
      if (t - time > analytic + dt) ++slower;
    } else {
      EXPECT_NEAR(t - time, analytic, dt + 1e-9) << "sequence " << s;
    }
    ASSERT_TRUE(tragen.getCurrentSetpoint(t + dt, sp));
    for (int i = 0; i < 6; ++i) {
      ASSERT_NEAR(sp.position(i), last(i), 1e-12) << "sequence " << s;
      ASSERT_EQ(sp.velocity(i), 0.0);
      ASSERT_EQ(sp.acceleration(i), 0.0);
    }
  }
  // Nearly every via point of a blended sequence is blended. A via point is passed at rest only
  // when neither overlapping the two motions nor a quintic at most three times as long as stopping
  // keeps the limits (0.7 % of these random via points, the joints synchronised in time).
  EXPECT_GT(blends, vias * 98 / 100);
  RecordProperty("sequences", sequences);
  RecordProperty("segments", static_cast<int>(segments));
  RecordProperty("blends", static_cast<int>(blends));
  RecordProperty("samples", static_cast<int>(samples));
  // Blending saves time overall.
  EXPECT_LT(blendedTime, unblendedTime);
  std::printf("%d sequences, %ld segments, %ld of %ld via points blended, %ld setpoints checked; the blended sequences "
              "take %.4f of their unblended time (%ld of %d longer)\n",
              sequences, segments, blends, vias, samples, blendedTime / unblendedTime, slower, sequences / 2);
  clock.resume();
}

}  // namespace
}  // namespace rp
