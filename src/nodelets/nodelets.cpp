// Every node as a nodelet: the same wrapper class, constructed in onInit() with the nodelet's handles,
// so a manager can pass the lockstep messages as shared pointers without serialisation.
//
// The callback-driven nodelets of one manager share one callback queue served by one thread, instead of
// the manager's pool. The pool hands every callback from a dispatcher thread to a worker: two thread
// wake-ups per message, and a lockstep step is a chain of messages (state -> kinematic -> torque, plus
// the reference, seed drill and monitor). On one shared thread a message published from a callback is
// queued behind it and taken by the same thread without any wake-up; the plant's lockstep torque
// callback runs inline where the torque is published (on that thread too), so a whole step runs on one
// thread with no hand-over. None of these callbacks blocks, so sharing a thread cannot deadlock; each
// nodelet's callbacks stay serialised, as with getNodeHandle().
#include <nodelet/nodelet.h>
#include <ros/callback_queue.h>
#include <ros/spinner.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>
#include <mutex>
#include <thread>

#include "sowing_robot/ros/bag/bag_recorder.h"
#include "sowing_robot/ros/cmd_vel_limiter.h"
#include "sowing_robot/ros/common/failure_log.h"
#include "sowing_robot/ros/kinematic_controller.h"
#include "sowing_robot/ros/plant_sim/plant_sim.h"
#include "sowing_robot/ros/reference_generator.h"
#include "sowing_robot/ros/run_monitor.h"
#include "sowing_robot/ros/seed_drill.h"
#include "sowing_robot/ros/state_estimator.h"
#include "sowing_robot/ros/torque_controller.h"

namespace sowing_robot {

/// The callback queue and thread shared by the nodelets of this library in one manager; it lives while
/// any of them holds it.
class SharedCallbackThread {
 public:
  static std::shared_ptr<SharedCallbackThread> acquire() {
    static std::mutex mutex;
    static std::weak_ptr<SharedCallbackThread> current;
    std::lock_guard<std::mutex> lock(mutex);
    std::shared_ptr<SharedCallbackThread> p = current.lock();
    if (!p) {
      p = std::shared_ptr<SharedCallbackThread>(new SharedCallbackThread);
      current = p;
    }
    return p;
  }
  ros::CallbackQueue* queue() { return &queue_; }

 private:
  SharedCallbackThread() : spinner_(1, &queue_) { spinner_.start(); }
  ros::CallbackQueue queue_;
  ros::AsyncSpinner spinner_;  // after queue_: stopped (destroyed) before it
};

/// Callback-driven nodes: the wrapper lives as long as the nodelet.
///
/// A wrapper that cannot start (NodeFailure: a bad parameter) is logged as this nodelet's one FATAL line
/// and rethrown. nodelet::Loader::load (nodelet 1.10, Debian 12) catches any exception from init(),
/// erases the nodelet and returns false: the load_nodelet service fails, `nodelet load` exits non-zero,
/// and the manager with its other nodelets runs on (upstream's test_nodelet/FailingNodelet relies on
/// the same). Swallowing the error instead would leave an inert nodelet that claims to be loaded.
/// Nothing is created on the Nodelet's own callback queues before the throw, so 1.10's order of
/// destruction after a failed init (the queues before the nodelet; fixed upstream in 1.11) finds no
/// subscription of ours to tear down on a freed queue.
template <typename Wrapper>
class WrapperNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    thread_ = SharedCallbackThread::acquire();
    ros::NodeHandle nh = getNodeHandle(), pnh = getPrivateNodeHandle();
    nh.setCallbackQueue(thread_->queue());
    pnh.setCallbackQueue(thread_->queue());
    try {
      impl_ = std::make_unique<Wrapper>(nh, pnh);
    } catch (const NodeFailure& failure) {
      logFailure(getName(), failure);  // the nodelet's name: the manager's would say nothing
      throw;
    }
  }
  // impl_ (its subscriptions) goes before the queue it uses.
  std::shared_ptr<SharedCallbackThread> thread_;
  std::unique_ptr<Wrapper> impl_;
};

using KinematicControllerNodelet = WrapperNodelet<KinematicController>;
using TorqueControllerNodelet = WrapperNodelet<TorqueController>;
using ReferenceGeneratorNodelet = WrapperNodelet<ReferenceGenerator>;
using RunMonitorNodelet = WrapperNodelet<RunMonitor>;
using SeedDrillNodelet = WrapperNodelet<SeedDrillNode>;
using StateEstimatorNodelet = WrapperNodelet<StateEstimator>;
using CmdVelLimiterNodelet = WrapperNodelet<CmdVelLimiter>;
// The recorder in the pipeline's manager: the 1 kHz topics it throttles come as pointers on the shared thread
// instead of over TCP to a process of its own (each message sent, and the recorder woken, per step). It
// closes the bag when the manager unloads it.
using RecorderNodelet = WrapperNodelet<BagRecorder>;

/// The plant's run() on a thread of its own: in lockstep it only supervises (the torque callback steps);
/// in realtime it paces the steps and serves the wheel_torque queue. A run that cannot go on (the state
/// diverged, or lockstep gave up) is logged as this nodelet's one FATAL line and ends there: nothing more
/// is stepped or published, and the manager and its other nodelets run on.
class PlantSimNodelet : public nodelet::Nodelet {
 public:
  ~PlantSimNodelet() override {
    if (impl_) impl_->stop();
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override {
    // Its subscriptions (the plan, and traction_control/state once per step, for the no-traction diagnosis)
    // go on the shared thread too: on the nodelet's own queue each message would be handed from the manager's
    // dispatcher thread to a worker, two thread wake-ups per step. None of them blocks; the lockstep torque
    // callback keeps its own inline queue.
    shared_ = SharedCallbackThread::acquire();
    ros::NodeHandle nh = getNodeHandle(), pnh = getPrivateNodeHandle();
    nh.setCallbackQueue(shared_->queue());
    pnh.setCallbackQueue(shared_->queue());
    try {
      impl_ = std::make_unique<PlantSim>(nh, pnh);
    } catch (const NodeFailure& failure) {
      logFailure(getName(), failure);  // as WrapperNodelet: logged, and the loader unloads it
      throw;
    }
    thread_ = std::thread([this] {
      try {
        impl_->run();
      } catch (const NodeFailure& failure) {
        logFailure(getName(), failure);  // the nodelet's name, not the manager's
        return;
      }
      if (impl_->exitAtEnd()) ros::shutdown();
    });
  }
  std::shared_ptr<SharedCallbackThread> shared_;  // before impl_: outlives its subscriptions
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
PLUGINLIB_EXPORT_CLASS(sowing_robot::StateEstimatorNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::CmdVelLimiterNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sowing_robot::RecorderNodelet, nodelet::Nodelet)
