// plant_sim's sensors: the core's sensor suite (core/simulation/sensor_feeds.h: the seeded sensors of
// core/model/sensors.h, read on the plant's true state exactly as the in-process loop reads them), and their
// messages. Topics (relative, docs/sensors.md):
//   odom  nav_msgs/Odometry                    encoder dead reckoning (nominal R, L), every step; its
//                                              pose covariance grows; odom -> base_link tf from it
//   imu   sensor_msgs/Imu                      yaw rate (omega + bias + noise), every step
//   fix   geometry_msgs/PoseWithCovarianceStamped  the axle midpoint + noise at sensors/fix/rate,
//                                              stamped with its measurement time, sent latency later
// The true state goes out on ground_truth (SimulatedPlant). update() reads the sensors once per plant
// step; publish() sends what they read, and may be called again for the same step (a lockstep re-send:
// the same odom and imu again, no fix twice).
// Each topic is one registration in the constructor (sensors.cpp): its name, its message's set-up (frames, the
// constant covariances) and its fill from the suite's last reading; a new sensor's message is one more.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>

#include <memory>
#include <string>
#include <vector>

#include "sowing_robot/core/model/plant.h"
#include "sowing_robot/core/model/robot_params.h"
#include "sowing_robot/core/model/sensors.h"
#include "sowing_robot/core/simulation/sensor_feeds.h"
#include "sowing_robot/ros/common/msg_checks.h"

namespace sowing_robot {

/// What a sensor topic's message set-up reads (PlantSensors' registrations).
struct SensorTopicSetup {
  const core::SensorParams& params;
  const core::RobotParams& nominal;  ///< the robot the encoders' dead reckoning assumes
  const core::SensorSuite& suite;
  const std::string &odom_frame, &base_frame;
};

class PlantSensors {
 public:
  /// Starts every sensor at `initial` (time 0) and advertises odom, imu and fix on nh. `nominal`: the
  /// robot the encoders' dead reckoning assumes (the URDF's R and L). Throws std::invalid_argument for
  /// invalid parameters (the node validated them before).
  PlantSensors(ros::NodeHandle nh, const core::SensorParams& params, const core::RobotParams& nominal,
               const core::State& initial, const std::string& odom_frame, const std::string& base_frame);

  /// Reads every sensor at the true state `s` at time t, dt after the previous reading.
  void update(double t, const core::State& s, double dt);
  /// odom and imu of the last reading and the fixes whose latency has passed, stamped `stamp` (the fix
  /// with its measurement time).
  void publish(const ros::Time& stamp);
  /// The odom -> base_link transform of the last odom published.
  geometry_msgs::TransformStamped odomTransform() const;
  unsigned odomSubscribers() const { return odom_->publisher().getNumSubscribers(); }

 private:
  using Setup = SensorTopicSetup;
  /// One sensor's topic: its message, set up once and filled and sent at every publish().
  class Topic {
   public:
    virtual ~Topic() = default;
    virtual void publish(core::SensorSuite& suite, const ros::Time& stamp) = 0;
  };
  template <class Msg>
  class TopicOf final : public Topic {
   public:
    /// The fields that never change.
    using Init = void (*)(Msg& msg, const Setup& setup);
    /// The suite's last reading into msg, stamped `stamp`, sent on pub (publishShared): once, or once per delivered
    /// measurement (none when none is due).
    using Fill = void (*)(core::SensorSuite& suite, Msg& msg, const ros::Time& stamp, const ros::Publisher& pub);
    TopicOf(ros::NodeHandle& nh, const char* topic, Init init, Fill fill, const Setup& setup)
        : pub_(nh.advertise<Msg>(topic, kLockstepQueue)), fill_(fill) {
      init(msg_, setup);
    }
    void publish(core::SensorSuite& suite, const ros::Time& stamp) override { fill_(suite, msg_, stamp, pub_); }
    const Msg& message() const { return msg_; }
    const ros::Publisher& publisher() const { return pub_; }

   private:
    ros::Publisher pub_;
    Fill fill_;
    Msg msg_;
  };
  /// Advertises `topic` and sets its message up; publish() then sends it, in the order of the registrations.
  template <class Msg>
  const TopicOf<Msg>* add(ros::NodeHandle& nh, const char* topic, typename TopicOf<Msg>::Init init,
                          typename TopicOf<Msg>::Fill fill, const Setup& setup) {
    topics_.push_back(std::make_unique<TopicOf<Msg>>(nh, topic, init, fill, setup));
    return static_cast<const TopicOf<Msg>*>(topics_.back().get());
  }

  core::SensorParams params_;
  core::SensorSuite sensors_;
  double time_ = 0.0;
  std::vector<std::unique_ptr<Topic>> topics_;
  const TopicOf<nav_msgs::Odometry>* odom_ = nullptr;  // odomTransform() and odomSubscribers() read it
};

}  // namespace sowing_robot
