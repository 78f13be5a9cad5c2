// A growing nav_msgs/Path for rviz (travelled path, reference path), shared by plant_sim and
// reference_generator: a point every `spacing` metres, at most kMaxPoses (the oldest half dropped when
// full), and re-sent only every `publish_every`-th point, because the message grows with the run and
// must not be re-serialised at the control rate.
#pragma once

#include <nav_msgs/Path.h>

#include <cmath>
#include <string>

namespace sowing_robot {

class PathBuffer {
 public:
  static constexpr std::size_t kMaxPoses = 20000;

  PathBuffer(const std::string& frame, double spacing, int publish_every)
      : spacing_(spacing), publish_every_(publish_every) {
    path_.header.frame_id = frame;
  }

  /// Appends `pose` if it lies at least `spacing` from the last point. True when the path should be
  /// published now (the first point, then every publish_every-th).
  bool add(const geometry_msgs::PoseStamped& pose) {
    if (!path_.poses.empty()) {
      const auto& last = path_.poses.back().pose.position;
      if (std::hypot(pose.pose.position.x - last.x, pose.pose.position.y - last.y) < spacing_) return false;
    }
    if (path_.poses.size() >= kMaxPoses) path_.poses.erase(path_.poses.begin(), path_.poses.begin() + kMaxPoses / 2);
    path_.poses.push_back(pose);
    path_.header.stamp = pose.header.stamp;
    return added_++ % publish_every_ == 0;
  }

  const nav_msgs::Path& path() const { return path_; }

 private:
  double spacing_;
  int publish_every_;
  long added_ = 0;
  nav_msgs::Path path_;
};

}  // namespace sowing_robot
