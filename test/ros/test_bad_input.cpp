// Bad inputs: every malformed scan of the issue (REP 117 values, bad angles, empty,
// empty / unknown frame, stamp too old for tf, time jumping backwards, bad range limits)
// is counted by reason; the node stays up and keeps integrating; the map is unchanged where the
// dropped scans would have changed it. A tf1-style '/' frame id is stripped, and its scan used; a
// range count disagreeing with the angles, and intensities of another length, are integrated
// (counted). Odometry jumping to an absurd pose for one tf sample and back: the scan there is
// refused as absurd_pose, the map keeps its size, mapping goes on at the next sane pose.
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

std::mutex g_mutex;
nav_msgs::OccupancyGrid::ConstPtr g_map;
wavog_mapping::MapperStatus::ConstPtr g_status;
ros::Publisher g_scan_pub;

nav_msgs::OccupancyGrid::ConstPtr lastMap() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_map;
}

/// Waits until `pred(status)` holds (or the timeout); returns the last status.
template <typename Pred>
wavog_mapping::MapperStatus::ConstPtr waitStatus(Pred pred, double timeout) {
  return room::waitLatest(
      &g_mutex, &g_status,
      [&pred](const wavog_mapping::MapperStatus& s) {
        return s.inputs.size() == 1 && pred(s.inputs[0]);
      },
      timeout);
}

/// A well-formed scan of laser_1 whose every beam sees a phantom wall at 1 m: integrating it
/// would mark the free cell 1 m ahead of laser_1 occupied.
sensor_msgs::LaserScan::Ptr phantom() {
  auto scan = room::scanOf(room::sensors()[0], ros::Time::now());
  std::fill(scan->ranges.begin(), scan->ranges.end(), 1.0f);
  return scan;
}

/// Map point 1 m ahead of laser_1.
void phantomPoint(double* x, double* y) { room::aheadOf(room::sensors()[0], 1.0, x, y); }

void publishGood(int n) {
  for (int i = 0; i < n; ++i) {
    g_scan_pub.publish(room::scanOf(room::sensors()[0], ros::Time::now()));
    ros::WallDuration(0.1).sleep();
  }
}

TEST(BadInput, EveryReasonCountedNodeStaysUpMapUnchanged) {
  publishGood(5);
  auto s = waitStatus([](const wavog_mapping::InputStatus& in) { return in.integrated >= 3; }, 20);
  ASSERT_TRUE(s);
  ASSERT_GE(s->inputs[0].integrated, 3u);
  double px = 0, py = 0;
  phantomPoint(&px, &py);
  {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(10);
    while (ros::WallTime::now() < end && !(lastMap() && room::cellAt(*lastMap(), px, py) >= 0)) {
      ros::WallDuration(0.05).sleep();
    }
  }
  ASSERT_TRUE(lastMap());
  const int before = room::cellAt(*lastMap(), px, py);
  ASSERT_GE(before, 0);
  ASSERT_LT(before, 35) << "the probe must be free before the bad scans";
  // The node must hold moving_laser's tf before the too-old scan comes, or that scan waits for an
  // unknown frame instead of being too old (seen under ThreadSanitizer on a loaded machine): good
  // scans from moving_laser (laser_1's pose) until one is integrated.
  s = waitStatus([](const wavog_mapping::InputStatus& in) { return in.integrated >= 5; }, 20);
  ASSERT_TRUE(s);
  const std::uint64_t good = s->inputs[0].integrated;
  const ros::WallTime tf_end = ros::WallTime::now() + ros::WallDuration(20);
  while (ros::WallTime::now() < tf_end && s->inputs[0].integrated <= good) {
    auto moving = room::scanOf(room::sensors()[0], ros::Time::now());
    moving->header.frame_id = "moving_laser";
    g_scan_pub.publish(moving);
    s = waitStatus([good](const wavog_mapping::InputStatus& in) { return in.integrated > good; },
                   1.0);
    ASSERT_TRUE(s);
  }
  ASSERT_GT(s->inputs[0].integrated, good) << "moving_laser's tf never reached the node";
  const std::uint64_t integrated_before = s->inputs[0].integrated;

  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();

  auto empty = phantom();
  empty->ranges.clear();
  g_scan_pub.publish(empty);

  // Not bad (issue 27): a range count disagreeing with the angles (beam i at angle_min + i *
  // angle_increment, angle_max unused, as laser_geometry does) and intensities of another length
  // are integrated, each counted.
  auto size_mismatch = room::scanOf(room::sensors()[0], ros::Time::now());
  size_mismatch->ranges.resize(100);
  size_mismatch->intensities.assign(3, 1.0f);
  g_scan_pub.publish(size_mismatch);

  auto zero_inc = phantom();
  zero_inc->angle_increment = 0.0f;
  g_scan_pub.publish(zero_inc);

  auto nan_inc = phantom();
  nan_inc->angle_increment = nan;
  g_scan_pub.publish(nan_inc);

  auto no_frame = phantom();
  no_frame->header.frame_id = "";
  g_scan_pub.publish(no_frame);

  // A tf1-style frame id is not bad: the slash is stripped (warned once) and the scan integrated.
  auto slash = room::scanOf(room::sensors()[0], ros::Time::now());
  slash->header.frame_id = "/laser_1";
  g_scan_pub.publish(slash);

  auto all_nan = phantom();
  std::fill(all_nan->ranges.begin(), all_nan->ranges.end(), nan);
  g_scan_pub.publish(all_nan);

  auto bad_limits = phantom();
  bad_limits->range_min = 50.0f;
  bad_limits->range_max = 10.0f;
  g_scan_pub.publish(bad_limits);

  auto too_old = phantom();
  too_old->header.frame_id = "moving_laser";
  too_old->header.stamp = ros::Time::now() - ros::Duration(60.0);
  g_scan_pub.publish(too_old);
  ros::WallDuration(0.2).sleep();

  // Unknown frames wait in the tf queue (queue_size 2) until pushed out.
  for (int i = 0; i < 4; ++i) {
    auto unknown = phantom();
    unknown->header.frame_id = "no_such_frame";
    g_scan_pub.publish(unknown);
    ros::WallDuration(0.02).sleep();
  }
  ros::WallDuration(0.2).sleep();

  // REP 117 values inside a valid scan: used per beam, the scan is integrated.
  auto rep117 = room::scanOf(room::sensors()[0], ros::Time::now());
  rep117->ranges[0] = nan;
  rep117->ranges[1] = inf;
  rep117->ranges[2] = -inf;
  rep117->ranges[3] = 0.01f;  // below range_min
  g_scan_pub.publish(rep117);
  ros::WallDuration(0.1).sleep();

  // Time jumping backwards (as when a bag restarts): counted, and mapping goes on.
  auto jumped = room::scanOf(room::sensors()[0], ros::Time::now() - ros::Duration(5.0));
  g_scan_pub.publish(jumped);
  ros::WallDuration(0.1).sleep();
  publishGood(5);

  s = waitStatus(
      [&](const wavog_mapping::InputStatus& in) {
        return in.integrated >= integrated_before + 9 && in.dropped_tf_unavailable >= 1 &&
               in.dropped_tf_too_old >= 1;
      },
      20);
  ASSERT_TRUE(s);
  const auto& in = s->inputs[0];
  EXPECT_EQ(in.dropped_empty, 1u);
  EXPECT_EQ(in.beam_count_mismatches, 1u);
  EXPECT_EQ(in.intensities_ignored, 1u);
  EXPECT_EQ(in.dropped_bad_angles, 2u);
  EXPECT_EQ(in.dropped_bad_frame, 1u);  // the empty frame_id
  EXPECT_EQ(in.dropped_no_valid_beam, 1u);
  EXPECT_EQ(in.dropped_bad_geometry, 1u);
  EXPECT_EQ(in.dropped_tf_too_old, 1u);
  EXPECT_GE(in.dropped_tf_unavailable, 1u);
  EXPECT_GE(in.time_jumps, 1u);
  EXPECT_GE(in.beams_invalid, 3u);
  EXPECT_GE(in.beams_no_return, 1u);
  // the mismatched one, slashed, REP 117, jumped, 5 good ones
  EXPECT_GE(in.integrated, integrated_before + 9);
  EXPECT_EQ(in.dropped_absurd_pose + in.dropped_out_of_extent, 0u);
  EXPECT_GT(in.beams_hit, 0u);
  EXPECT_GT(in.nodes_visited, 0u);
  EXPECT_GT(in.blocks_touched, 0u);
  EXPECT_EQ(s->tf_failures, in.dropped_tf_unavailable + in.dropped_tf_too_old);

  // The map after the next publication: the phantom wall never made it in.
  const ros::Time after = ros::Time::now();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(10);
  while (ros::WallTime::now() < end && !(lastMap() && lastMap()->header.stamp > after)) {
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(lastMap());
  const int after_value = room::cellAt(*lastMap(), px, py);
  EXPECT_GE(after_value, 0);
  EXPECT_LT(after_value, 35) << "a dropped scan changed the map";
  EXPECT_GT(room::cellAt(*lastMap(), room::kOccX, room::kOccY), 65);
}

TEST(BadInput, AbsurdPoseFromTfRefusedMapKeptMappingGoesOn) {
  auto s = waitStatus([](const wavog_mapping::InputStatus& in) { return in.integrated >= 1; }, 20);
  ASSERT_TRUE(s);
  const wavog_mapping::InputStatus before = s->inputs[0];
  const std::uint64_t layers_refused = s->layers_refused;
  // jumpy_laser sits where laser_1 is, by tf samples every 0.1 s, but one sample (as the oko bag's
  // odometry) puts it 2.76e7 m away: inside the extent at 5 cm, so the core would map it there.
  const ros::Time t0 = ros::Time::now() - ros::Duration(2.0);
  const tf2::Transform sane = room::sensorInBase(room::sensors()[0]);
  std::vector<geometry_msgs::TransformStamped> samples;
  for (int k = 0; k <= 20; ++k) {
    tf2::Transform t = sane;
    if (k == 10) t.setOrigin(tf2::Vector3(sane.getOrigin().x(), -2.76e7, 0.0));
    samples.push_back(room::toMsg(t, "base_link", "jumpy_laser"));
    samples.back().header.stamp = t0 + ros::Duration(0.1 * k);
  }
  tf2_ros::TransformBroadcaster tf;
  tf.sendTransform(samples);
  ros::WallDuration(0.3).sleep();
  auto at = [&](double dt, bool wall) {
    auto scan = wall ? room::scanOf(room::sensors()[0], t0 + ros::Duration(dt)) : phantom();
    scan->header.frame_id = "jumpy_laser";
    scan->header.stamp = t0 + ros::Duration(dt);
    scan->time_increment = 0.0f;  // one pose per scan: the sample itself
    return scan;
  };
  g_scan_pub.publish(at(0.3, true));  // sane: the reference
  ros::WallDuration(0.2).sleep();
  g_scan_pub.publish(at(1.0, false));  // the phantom wall at the absurd sample
  ros::WallDuration(0.2).sleep();
  g_scan_pub.publish(at(1.7, true));  // sane again: mapped
  s = waitStatus(
      [&](const wavog_mapping::InputStatus& in) {
        return in.integrated >= before.integrated + 2 &&
               in.dropped_absurd_pose > before.dropped_absurd_pose;
      },
      20);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->inputs[0].dropped_absurd_pose, before.dropped_absurd_pose + 1);
  EXPECT_EQ(s->inputs[0].integrated, before.integrated + 2);
  // The map keeps its size (one scan 2.76e7 m away would make every layer too large to publish)
  // and the phantom wall is nowhere in it.
  const ros::Time after = ros::Time::now();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(10);
  while (ros::WallTime::now() < end && !(lastMap() && lastMap()->header.stamp > after)) {
    ros::WallDuration(0.05).sleep();
  }
  ASSERT_TRUE(lastMap());
  s = waitStatus([](const wavog_mapping::InputStatus&) { return true; }, 1);
  EXPECT_EQ(s->layers_refused, layers_refused);
  EXPECT_LT(lastMap()->info.width, 1000u);
  EXPECT_LT(lastMap()->info.height, 1000u);
  double px = 0, py = 0;
  phantomPoint(&px, &py);
  EXPECT_LT(room::cellAt(*lastMap(), px, py), 35) << "the refused scan changed the map";
  EXPECT_GT(room::cellAt(*lastMap(), room::kOccX, room::kOccY), 65);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bad_input");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  // A moving frame (dynamic tf at 20 Hz) for the stamp-too-old case.
  tf2_ros::TransformBroadcaster tf;
  std::atomic<bool> running{true};
  std::thread tf_thread([&] {
    ros::WallRate rate(20.0);
    while (running && ros::ok()) {
      tf.sendTransform(
          room::toMsg(room::sensorInBase(room::sensors()[0]), "base_link", "moving_laser"));
      rate.sleep();
    }
  });
  g_scan_pub = nh.advertise<sensor_msgs::LaserScan>("scan_1", 50);
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  room::waitForSubscribers(g_scan_pub, 1, 20.0);  // the node, before the first scan
  const int result = RUN_ALL_TESTS();
  running = false;
  tf_thread.join();
  return result;
}
