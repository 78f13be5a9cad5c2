#include "sowing_robot/core/model/contact.h"

#include <cstdio>
#include <stdexcept>

namespace sowing_robot {
namespace core {

ContactMonitor::ContactMonitor(Footprint footprint, std::vector<Obstacle> obstacles)
    : footprint_(std::move(footprint)) {
  if (!footprint_.empty()) {
    const std::string e = footprint_.validate();
    if (!e.empty()) throw std::invalid_argument("ContactMonitor: " + e);
  }
  setObstacles(std::move(obstacles));
}

void ContactMonitor::setObstacles(std::vector<Obstacle> obstacles) {
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const std::string e = obstacles[i].validate();
    if (!e.empty()) throw std::invalid_argument("obstacles[" + std::to_string(i) + "]: " + e);
  }
  closeAll();
  obstacles_ = std::move(obstacles);
  open_.assign(obstacles_.size(), -1);
}

void ContactMonitor::closeAll() {
  for (long& k : open_) {
    if (k >= 0) events_[static_cast<std::size_t>(k)].ongoing = false;
    k = -1;
  }
}

void ContactMonitor::finish() { closeAll(); }

bool ContactMonitor::inContact() const {
  for (long k : open_)
    if (k >= 0) return true;
  return false;
}

bool ContactMonitor::update(double t, const Pose2D& pose) {
  if (!allFinite(t, pose.x, pose.y, pose.theta)) {
    ++rejected_;
    return false;
  }
  bool changed = false;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const Obstacle& o = obstacles_[i];
    const double d = footprint_.distanceToCircle(pose, {o.x, o.y}, o.radius);
    if (d < nearest) nearest = d;
    if (d < min_clearance_) {
      min_clearance_ = d;
      min_obstacle_ = i;
      min_time_ = t;
    }
    long& k = open_[i];
    if (d < 0.0) {
      if (k < 0) {
        ContactEvent e;
        e.obstacle = i;
        e.start = t;
        events_.push_back(e);
        k = static_cast<long>(events_.size()) - 1;
        changed = true;
      }
      ContactEvent& e = events_[static_cast<std::size_t>(k)];
      e.end = t;
      if (-d > e.max_depth) e.max_depth = -d;
    } else if (k >= 0) {
      events_[static_cast<std::size_t>(k)].ongoing = false;
      k = -1;
      changed = true;
    }
  }
  last_clearance_ = nearest;
  return changed;
}

std::string ContactMonitor::report() const {
  char b[200];
  std::string out;
  std::snprintf(b, sizeof(b), "body clearance: min %.3f m (obstacle %zu at t = %.3f s); contacts: %zu\n",
                min_clearance_, min_obstacle_, min_time_, events_.size());
  out += b;
  for (const ContactEvent& e : events_) {
    std::snprintf(b, sizeof(b), "  contact with obstacle %zu: t = %.3f .. %.3f s, max depth %.3f m%s\n", e.obstacle,
                  e.start, e.end, e.max_depth, e.ongoing ? " (ongoing)" : "");
    out += b;
  }
  return out;
}

}  // namespace core
}  // namespace sowing_robot
