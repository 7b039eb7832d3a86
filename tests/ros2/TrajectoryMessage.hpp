// A trajectory_msgs/JointTrajectory built from C++ values for the tests (Ros2Trajectory_test and
// the writer in another process, ros2_trajectory_writer): the C struct idlc generates from
// src/ros2/idl/trajectory_msgs.idl, pointing into this object's storage.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "trajectory_msgs.h"

namespace rp::test {

struct TrajectoryMessage {
  struct Point {
    double time = 0;  // time_from_start [s] (negative ones too, to test their refusal)
    std::vector<double> positions, velocities, accelerations;
  };
  std::vector<std::string> names;
  std::vector<Point> points;
  double stamp = 0;  // header.stamp [s since the epoch]; 0: start on receipt

  // The message, valid while this object lives unchanged.
  const trajectory_msgs_msg_dds__JointTrajectory_& message() {
    namePointers_.clear();
    for (std::string& n : names) namePointers_.push_back(n.data());
    ddsPoints_.assign(points.size(), trajectory_msgs_msg_dds__JointTrajectoryPoint_{});
    for (std::size_t k = 0; k < points.size(); ++k) {
      auto& d = ddsPoints_[k];
      set(d.positions, points[k].positions);
      set(d.velocities, points[k].velocities);
      set(d.accelerations, points[k].accelerations);
      const double sec = std::floor(points[k].time);
      d.time_from_start.sec = static_cast<int32_t>(sec);
      d.time_from_start.nanosec = static_cast<uint32_t>(std::lround((points[k].time - sec) * 1e9) % 1000000000);
    }
    msg_ = {};
    const double sec = std::floor(stamp);
    msg_.header.stamp.sec = static_cast<int32_t>(sec);
    msg_.header.stamp.nanosec = static_cast<uint32_t>((stamp - sec) * 1e9);
    msg_.header.frame_id = frameId_.data();
    msg_.joint_names._buffer = namePointers_.data();
    msg_.joint_names._length = msg_.joint_names._maximum = static_cast<uint32_t>(namePointers_.size());
    msg_.points._buffer = ddsPoints_.data();
    msg_.points._length = msg_.points._maximum = static_cast<uint32_t>(ddsPoints_.size());
    return msg_;
  }

 private:
  static void set(dds_sequence_double& s, std::vector<double>& v) {
    s._buffer = v.data();
    s._length = s._maximum = static_cast<uint32_t>(v.size());
    s._release = false;
  }
  std::vector<char*> namePointers_;
  std::vector<trajectory_msgs_msg_dds__JointTrajectoryPoint_> ddsPoints_;
  std::string frameId_;
  trajectory_msgs_msg_dds__JointTrajectory_ msg_{};
};

}  // namespace rp::test
