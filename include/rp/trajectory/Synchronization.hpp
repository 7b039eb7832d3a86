#pragma once
/// @file
/// How the joints of one joint-space motion are timed against each other.

namespace rp {

/// How the joints of a joint-space motion are synchronised (the modes Ruckig's users know).
enum class Synchronization {
  /// All joints start and end together at the shortest common duration; each joint follows its
  /// own jerk-limited profile of exactly that duration (the path in joint space is in general not
  /// a straight line). From rest to rest that duration is the slowest joint's minimum. The default
  /// for joint moves.
  Time,
  /// All joints follow one normalised profile: the straight line in joint space, every joint
  /// starting and ending together. As long as Time or longer (up to about 10 % with limits that
  /// differ per joint).
  Phase,
  /// Each joint moves on its own minimum time; the motion ends when the slowest joint does.
  None,
};

/// The mode's name as rp-plan's --sync takes it: "time", "phase" or "none".
/// @param[in] mode  a synchronisation mode
/// @return a static string
inline const char* toString(Synchronization mode) {
  switch (mode) {
    case Synchronization::Time: return "time";
    case Synchronization::Phase: return "phase";
    case Synchronization::None: return "none";
  }
  return "?";
}

}  // namespace rp
