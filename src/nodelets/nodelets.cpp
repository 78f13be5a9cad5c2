// Every node as a nodelet: the same wrapper class, constructed in onInit() with the nodelet's handles,
// so a manager can pass the lockstep messages as shared pointers without serialisation.
//
// Each nodelet serves its callbacks on a thread of its own rather than the manager's pool: the pool
// hands every callback from a dispatcher thread to a worker (two wake-ups per message), a dedicated
// thread takes it straight from the publisher (one). The lockstep loop is a chain of such hops, so this
// roughly halves the thread hand-overs on its critical path. A nodelet's callbacks stay serialised, as
// with getNodeHandle().
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/callback_queue.h>
#include <ros/spinner.h>

#include <memory>
#include <thread>

#include "sowing_robot/ros/kinematic_controller.h"
#include "sowing_robot/ros/plant_sim.h"
#include "sowing_robot/ros/reference_generator.h"
#include "sowing_robot/ros/run_monitor.h"
#include "sowing_robot/ros/seed_drill.h"
#include "sowing_robot/ros/torque_controller.h"

namespace sowing_robot {

/// Callback-driven nodes: the wrapper lives as long as the nodelet.
template <typename Wrapper>
class WrapperNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle nh = getNodeHandle(), pnh = getPrivateNodeHandle();
    nh.setCallbackQueue(&queue_);
    pnh.setCallbackQueue(&queue_);
    impl_ = std::make_unique<Wrapper>(nh, pnh);
    spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
    spinner_->start();
  }
  // Declared so that destruction stops the thread first, then drops the subscriptions, then the queue.
  ros::CallbackQueue queue_;
  std::unique_ptr<Wrapper> impl_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
};

using KinematicControllerNodelet = WrapperNodelet<KinematicController>;
using TorqueControllerNodelet = WrapperNodelet<TorqueController>;
using ReferenceGeneratorNodelet = WrapperNodelet<ReferenceGenerator>;
using RunMonitorNodelet = WrapperNodelet<RunMonitor>;
using SeedDrillNodelet = WrapperNodelet<SeedDrillNode>;

/// The plant runs its simulation loop on a thread of its own; the manager serves its callbacks.
class PlantSimNodelet : public nodelet::Nodelet {
 public:
  ~PlantSimNodelet() override {
    if (impl_) impl_->stop();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    impl_ = std::make_unique<PlantSim>(getNodeHandle(), getPrivateNodeHandle());
    thread_ = std::thread([this] {
      impl_->run();
      if (impl_->exitAtEnd()) ros::shutdown();
    });
  }
  std::unique_ptr<PlantSim> impl_;
  std::thread thread_;
};

}  // namespace sowing_robot

PLUGINLIB_EXPORT_CLASS(sowing_robot::PlantSimNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::KinematicControllerNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::TorqueControllerNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::ReferenceGeneratorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::RunMonitorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::SeedDrillNodelet, nodelet::Nodelet)
