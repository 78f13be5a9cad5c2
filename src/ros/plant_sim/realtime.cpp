#include "sowing_robot/ros/plant_sim/realtime.h"

#include "sowing_robot/core/common/validation.h"
#include "sowing_robot/ros/common/node_failure.h"

namespace sowing_robot {

RealtimeDriver::RealtimeDriver(ros::NodeHandle nh, SimulatedPlant& plant, const Config& config)
    : plant_(plant), cfg_(config) {
  torque_sub_ = subscribeTorque(nh, &queue_, [this](const WheelTorque::ConstPtr& m) { torqueCallback(m); });
}

RealtimeDriver::~RealtimeDriver() { torque_sub_.shutdown(); }

void RealtimeDriver::torqueCallback(const WheelTorque::ConstPtr& msg) {
  if (!core::allFinite(msg->right, msg->left)) {
    ++rejected_;
    ROS_WARN_THROTTLE(1.0, "plant_sim: rejected non-finite wheel torque (right %f, left %f); %ld so far", msg->right,
                      msg->left, rejected_);
    return;
  }
  torque_ = {msg->right, msg->left};
  tool_raised_ = msg->tool_raised;
  tool_depth_ = msg->tool_depth;
  torque_stamp_ = msg->header.stamp;
  torque_valid_ = true;
}

namespace {
// An empty callback: queued by stop() to end run()'s wait on the torque queue at once.
class WakeUp : public ros::CallbackInterface {
 public:
  CallResult call() override { return Success; }
};
}  // namespace

void RealtimeDriver::stop() {
  stop_ = true;
  queue_.addCallback(boost::make_shared<WakeUp>());
}

void RealtimeDriver::run() {
  const double dt = plant_.dt();
  const ros::WallTime wall_start = ros::WallTime::now();
  std::int64_t slipped = 0;
  for (std::int64_t k = 0; ros::ok() && !stop_; ++k) {
    const ros::Time stamp = plant_.stampOf(k);
    plant_.publish(k, plant_.visualStep(k));
    const ros::WallTime due = wall_start + ros::WallDuration((k + 1 - slipped) * dt / cfg_.realtime_factor);
    const ros::WallDuration remaining = due - ros::WallTime::now();
    if (remaining > ros::WallDuration(0)) {
      remaining.sleep();
    } else if (remaining < ros::WallDuration(-0.05)) {
      // More than 50 ms behind (an overloaded machine): slip the schedule instead of bursting steps,
      // which would run simulated time ahead of the controllers and trip their timeouts.
      slipped =
          k + 1 - static_cast<std::int64_t>((ros::WallTime::now() - wall_start).toSec() * cfg_.realtime_factor / dt);
      ROS_WARN_THROTTLE(10.0, "plant_sim: realtime fell behind the wall clock; slipping (machine overloaded?)");
    }
    queue_.callAvailable();  // every torque that came during the step; the newest is held
    core::WheelTorques u;
    const bool fresh = torque_valid_ && (stamp - torque_stamp_).toSec() <= cfg_.torque_timeout;
    if (fresh) u = torque_;
    plant_.setToolRaised(fresh && tool_raised_);     // a silent controller raises nothing: the drill's rule
    plant_.setToolDepth(fresh ? tool_depth_ : 0.0);  // nor sets a depth: the drill's nominal
    if (!fresh && torque_valid_) {
      ROS_WARN_THROTTLE(2.0, "plant_sim: no wheel_torque for %.3f s (timeout %.3f s): applying zero torque",
                        (stamp - torque_stamp_).toSec(), cfg_.torque_timeout);
    }
    if (!plant_.step(u, stamp)) throw NodeFailure(ExitCode::kDiverged, plant_.divergence());
  }
}

}  // namespace sowing_robot
