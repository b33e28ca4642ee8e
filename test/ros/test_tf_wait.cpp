// Scans waiting for late tf: the node's tf filter holds queue_size (2) scans per input; with more
// waiting it pushes the oldest out. Such scans must wait for tf and be placed when it comes (before
// the fix they were dropped as tf_unavailable, so a bag's map depended on how late tf came), and be
// dropped only at the bounds: more than subscriber_queue_size (50) waiting (tf stopped), or the
// newest transform of their frame more than tf_cache_time (10 s) after their stamp (tf_too_old).
// A scan whose stamp + tf_tolerance tf covers, but not its sweep's end, waits for that tf too:
// placed as soon as tf reached the stamp, it was compensated or not by how busy the host was.
// A scan stamped less than tf_tolerance before its frame's first transform is dropped (it held
// its input up until the end: fleet.test's intermittent failure).
// Each case on its own input, so that the scans one holds back do not hold up another's.
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/transform_broadcaster.h>

#include <mutex>
#include <string>
#include <vector>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;

/// A scan in `frame`: 200 beams over 2 rad seeing a wall at 2 m.
sensor_msgs::LaserScan::Ptr scanAt(const std::string& frame, const ros::Time& stamp) {
  auto s = boost::make_shared<sensor_msgs::LaserScan>();
  s->header.frame_id = frame;
  s->header.stamp = stamp;
  s->angle_min = -1.0f;
  s->angle_increment = 0.01f;
  s->angle_max = s->angle_min + 199 * s->angle_increment;
  s->range_min = 0.1f;
  s->range_max = 10.0f;
  s->ranges.assign(200, 2.0f);
  return s;
}

geometry_msgs::TransformStamped mapTo(const std::string& frame, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = "map";
  t.header.stamp = stamp;
  t.child_frame_id = frame;
  t.transform.rotation.w = 1.0;
  return t;
}

/// Waits until `pred` holds for input `i` of the status (or the timeout); returns the last status.
template <typename Pred>
wavog_mapping::MapperStatus::ConstPtr waitInput(std::size_t i, Pred pred, double timeout) {
  return room::waitLatest(
      &g_mutex, &g_status,
      [&](const wavog_mapping::MapperStatus& s) {
        return s.inputs.size() == 4 && pred(s.inputs[i]);
      },
      timeout);
}

/// Publishes `n` scans of `frame` at stamps `t0` + 0.1 s k, 20 ms apart (roscpp's queue of the
/// node, subscriber_queue_size 50, holds them however late the node takes them).
void publishScans(ros::Publisher& pub, const std::string& frame, const ros::Time& t0, int n) {
  for (int k = 0; k < n; ++k) {
    pub.publish(scanAt(frame, t0 + ros::Duration(0.1 * k)));
    ros::WallDuration(0.02).sleep();
  }
}

TEST(TfWait, PushedOutScansWaitForTfAndStopAtTheBounds) {
  ros::NodeHandle nh;
  auto sub = nh.subscribe<wavog_mapping::MapperStatus>(
      "/wavog_mapping/status", 10,
      boost::function<void(const wavog_mapping::MapperStatus::ConstPtr&)>(
          [](const wavog_mapping::MapperStatus::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(g_mutex);
            g_status = m;
          }));
  std::vector<ros::Publisher> pubs;
  for (const char* topic : {"scan_late", "scan_stopped", "scan_old", "scan_sweep"}) {
    pubs.push_back(nh.advertise<sensor_msgs::LaserScan>(topic, 100));
  }
  tf2_ros::TransformBroadcaster tf;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  for (auto& p : pubs) {
    while (p.getNumSubscribers() == 0 && ros::WallTime::now() < end) {
      ros::WallDuration(0.05).sleep();
    }
    ASSERT_GT(p.getNumSubscribers(), 0u);
  }
  ASSERT_TRUE(waitInput(
      0, [](const wavog_mapping::InputStatus&) { return true; }, 20.0));
  const ros::Time t0 = ros::Time::now();

  // Late: 10 scans before any tf of their frame (as at start-up, or tf starved on a loaded host):
  // 2 in the filter, 8 pushed out; then tf covering them all. Every scan is integrated.
  publishScans(pubs[0], "late", t0, 10);
  // Stopped: tf of the frame once, before the scans; 56 scans after it: 2 in the filter, the
  // memory bound (subscriber_queue_size 50) keeps 50 pushed out, drops 4.
  tf.sendTransform(mapTo("stopped", t0));
  publishScans(pubs[1], "stopped", t0 + ros::Duration(1.0), 56);
  // Old: tf 5 s before 4 scans, then 100 s after them (the buffer, 10 s long, forgets the first):
  // tf can never place them.
  tf.sendTransform(mapTo("old", t0 - ros::Duration(5.0)));
  publishScans(pubs[2], "old", t0, 4);
  // Sweep: tf up to 0.05 s after the stamp (tf_tolerance 0.03 s), then, after the scan has
  // passed the filter, beyond the sweep's 0.2 s. Before it, a scan stamped 0.02 s before the
  // frame's first transform: tf covers its stamp + tf_tolerance, never its stamp; it must be
  // dropped, not hold the input up.
  tf.sendTransform(std::vector<geometry_msgs::TransformStamped>{
      mapTo("sweep", t0 - ros::Duration(1.0)), mapTo("sweep", t0 + ros::Duration(0.05))});
  ros::WallDuration(0.2).sleep();
  pubs[3].publish(scanAt("sweep", t0 - ros::Duration(1.02)));
  ros::WallDuration(0.1).sleep();
  auto sweep = scanAt("sweep", t0);
  sweep->time_increment = static_cast<float>(0.2 / 199);
  pubs[3].publish(sweep);
  ros::WallDuration(0.5).sleep();
  tf.sendTransform(std::vector<geometry_msgs::TransformStamped>{
      mapTo("late", t0 - ros::Duration(1.0)), mapTo("late", t0 + ros::Duration(3.0)),
      mapTo("old", t0 + ros::Duration(100.0)), mapTo("sweep", t0 + ros::Duration(3.0))});

  const auto late = waitInput(
      0, [](const wavog_mapping::InputStatus& in) { return in.integrated >= 10; }, 20.0);
  ASSERT_TRUE(late);
  EXPECT_EQ(late->inputs[0].received, 10u);
  EXPECT_EQ(late->inputs[0].integrated, 10u) << late->inputs[0];
  EXPECT_EQ(late->inputs[0].dropped_tf_unavailable, 0u) << late->inputs[0];

  const auto swept = waitInput(
      3, [](const wavog_mapping::InputStatus& in) { return in.integrated >= 1; }, 20.0);
  ASSERT_TRUE(swept);
  EXPECT_EQ(swept->inputs[3].motion_fallbacks, 0u) << swept->inputs[3];
  EXPECT_EQ(swept->inputs[3].dropped_tf_too_old, 1u) << swept->inputs[3];

  const auto stopped = waitInput(
      1, [](const wavog_mapping::InputStatus& in) { return in.dropped_tf_unavailable >= 4; }, 20.0);
  ASSERT_TRUE(stopped);
  const auto old = waitInput(
      2, [](const wavog_mapping::InputStatus& in) { return in.dropped_tf_too_old >= 4; }, 20.0);
  ASSERT_TRUE(old);
  ros::WallDuration(1.0).sleep();  // nothing more may happen
  const auto s = waitInput(
      1, [](const wavog_mapping::InputStatus&) { return true; }, 5.0);
  ASSERT_TRUE(s);
  const auto& st = s->inputs[1];
  EXPECT_EQ(st.received, 56u);
  EXPECT_EQ(st.dropped_tf_unavailable, 4u) << st;
  EXPECT_EQ(st.integrated + st.dropped_tf_too_old, 0u) << st;
  const auto& od = s->inputs[2];
  EXPECT_EQ(od.received, 4u);
  EXPECT_EQ(od.dropped_tf_too_old, 4u) << od;
  EXPECT_EQ(od.integrated + od.dropped_tf_unavailable, 0u) << od;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tf_wait");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
