// plant_sim's contact check: the URDF's collision footprint at the simulated pose against the obstacles of
// the reference generator's plan, every step. It reports (topic `contacts`, the log, the final report);
// it does not model the contact. The footprint is published latched on `footprint` for rviz.
#pragma once

#include <ros/ros.h>

#include <mutex>
#include <string>
#include <vector>

#include "sowing_robot/Contact.h"
#include "sowing_robot/FieldPlan.h"
#include "sowing_robot/core/model/contact.h"

namespace sowing_robot {

class PlantContacts {
 public:
  /// `footprint` in base_link; obstacles come with the plan (none before it).
  PlantContacts(ros::NodeHandle nh, const core::Footprint& footprint, const std::string& odom_frame,
                const std::string& base_frame);
  /// The robot at `pose` at time t: publishes a Contact when a contact starts or ends.
  void update(double t, const core::Pose2D& pose);
  /// Closes the contacts in progress; the report (contacts, minimum body clearance) as text.
  std::string finish();

 private:
  void planCallback(const FieldPlan::ConstPtr& plan);
  void publish(const core::ContactEvent& e);

  std::mutex mutex_;  // the plan comes on another thread than the steps
  core::ContactMonitor monitor_;
  std::vector<core::Obstacle> obstacles_;
  std::vector<bool> reported_;  // per event: ongoing when last published
  std::string odom_frame_;
  ros::Publisher contact_pub_, footprint_pub_;
  ros::Subscriber plan_sub_;
};

}  // namespace sowing_robot
