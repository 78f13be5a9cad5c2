// rostest: watches a lockstep run of the node pipeline to its end, then checks the tracking result
// against the limits passed as <param>s and repeats the same scenario with the in-process runner
// (parameters read from the nodes' own namespaces, the outer/inner controller pair included): the
// metrics must agree bit for bit. ~expect_pair (optional, e.g. "rpp+pid") checks the pair read is the
// one the test means, so a fixture that silently fell back to kanayama+atsmc cannot pass.
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>

#include <cmath>

#include "sowing_robot/TrackingError.h"
#include "sowing_robot/core/simulation/runner.h"
#include "sowing_robot/ros/common/component_params.h"
#include "sowing_robot/ros/common/publisher_links.h"

using namespace sowing_robot;

namespace {
struct Watch {
  core::MetricsAccumulator metrics;
  TrackingError last;
  ros::Time last_stamp;
  bool any = false;
  long repeats = 0;
  void onOdom(const nav_msgs::Odometry::ConstPtr&) {}
  void onError(const TrackingError::ConstPtr& m) {
    if (any && m->header.stamp <= last_stamp) {
      ++repeats;
      return;
    }
    any = true;
    last_stamp = m->header.stamp;
    last = *m;
    metrics.add(m->header.stamp.toSec(), m->x, m->y, m->theta);
  }
};
}  // namespace

TEST(Pipeline, LockstepRunTracksTheLineAndEqualsTheInProcessRunner) {
  ros::NodeHandle nh, pnh("~");
  double max_ey = 0.02, max_etheta = 0.02, timeout = 150.0;
  pnh.getParam("max_final_ey", max_ey);
  pnh.getParam("max_final_etheta", max_etheta);
  pnh.getParam("wall_timeout", timeout);
  std::string expect_pair;
  pnh.getParam("expect_pair", expect_pair);

  core::Scenario sc;
  double duration = 0;
  const std::string err = loadPipelineScenario(sc, duration);
  ASSERT_TRUE(err.empty()) << err;
  std::printf("pipeline: controller pair %s\n", sc.controllerName().c_str());
  if (!expect_pair.empty()) ASSERT_EQ(sc.controllerName(), expect_pair);

  Watch w;
  ros::Subscriber sub = nh.subscribe("tracking_error", 100000, &Watch::onError, &w, ros::TransportHints().tcpNoDelay());
  // Linked as its publisher sees it before the run can start (publisher_links.h): a subscription merely made can lose
  // the first periods. Then ground_truth, counted by plant_sim's min_subscribers: the run starts once this listens.
  std::string unlinked;
  ASSERT_TRUE(waitUntilLinked({sub.getTopic()}, timeout, &unlinked)) << "no publisher linked " << unlinked;
  ros::Subscriber odom = nh.subscribe("ground_truth", 10, &Watch::onOdom, &w);
  const ros::WallTime start = ros::WallTime::now();
  while (ros::ok() && !(w.any && w.last_stamp.toSec() >= duration - 1e-9)) {
    ros::spinOnce();
    ros::WallDuration(0.001).sleep();
    ASSERT_LT((ros::WallTime::now() - start).toSec(), timeout) << "the pipeline did not finish the scenario";
  }
  const double wall = (ros::WallTime::now() - start).toSec();
  std::printf("pipeline: %zu periods, %.3f s simulated in about %.2f s wall\n", w.metrics.samples(), duration, wall);
  EXPECT_EQ(static_cast<std::int64_t>(w.metrics.samples()), sc.steps() + 1) << "a lockstep period was lost";
  EXPECT_LT(std::fabs(w.last.y), max_ey);
  EXPECT_LT(std::fabs(w.last.theta), max_etheta);

  core::LineReference ref(1.0, 3.0, 0.0);
  const core::RunResult in_process = core::runClosedLoop(sc, ref);
  const auto pipeline = w.metrics.result();
  std::printf("%s", core::metricsTable({"pipeline", "in-process"}, {pipeline, in_process.metrics}).c_str());
  for (int a = 0; a < core::AXIS_COUNT; ++a) {
    EXPECT_EQ(pipeline[a].ise, in_process.metrics[a].ise) << "axis " << a;
    EXPECT_EQ(pipeline[a].itae, in_process.metrics[a].itae) << "axis " << a;
    EXPECT_EQ(pipeline[a].settling_time, in_process.metrics[a].settling_time) << "axis " << a;
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "pipeline_tester");
  return RUN_ALL_TESTS();
}
