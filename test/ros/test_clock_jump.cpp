// A bag restarted with --clock: the ROS clock jumps backwards. The mapper clears its tf buffer,
// counts the jump and goes on integrating (sim time, /clock published by this test).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;
std::atomic<double> g_sim_time{1000.0};

template <typename Pred>
wavog_mapping::MapperStatus::ConstPtr waitStatus(Pred pred, double timeout) {
  return room::waitLatest(
      &g_mutex, &g_status,
      [&pred](const wavog_mapping::MapperStatus& s) { return s.inputs.size() == 1 && pred(s); },
      timeout);
}

TEST(ClockJump, TfClearedAndMappingGoesOn) {
  auto s = waitStatus(
      [](const wavog_mapping::MapperStatus& st) { return st.inputs[0].integrated >= 5; }, 30);
  ASSERT_TRUE(s);
  ASSERT_GE(s->inputs[0].integrated, 5u);
  EXPECT_EQ(s->clock_jumps, 0u);
  const std::uint64_t before = s->inputs[0].integrated;

  g_sim_time = g_sim_time - 500.0;  // the bag starts again

  s = waitStatus(
      [&](const wavog_mapping::MapperStatus& st) {
        return st.clock_jumps >= 1 && st.inputs[0].integrated >= before + 5;
      },
      30);
  ASSERT_TRUE(s);
  EXPECT_GE(s->clock_jumps, 1u);
  EXPECT_GE(s->inputs[0].time_jumps, 1u);
  EXPECT_GE(s->inputs[0].integrated, before + 5) << "mapping stopped after the clock jump";
  EXPECT_EQ(s->inputs[0].dropped_tf_too_old, 0u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_clock_jump");
  ros::NodeHandle nh;
  auto clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  auto scan_pub = nh.advertise<sensor_msgs::LaserScan>("scan_1", 10);
  std::atomic<bool> running{true};
  // Sim time advances with wall time; scans at 10 Hz stamped with sim time.
  std::thread clock([&] {
    int tick = 0;
    while (running) {
      rosgraph_msgs::Clock c;
      c.clock = ros::Time(g_sim_time.load());
      clock_pub.publish(c);
      if (tick++ % 10 == 0) scan_pub.publish(room::scanOf(room::sensors()[0], c.clock));
      ros::WallDuration(0.01).sleep();
      g_sim_time = g_sim_time + 0.01;
    }
  });
  ros::WallDuration(0.5).sleep();  // sim time known before tf is stamped
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  auto sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10, &g_mutex,
                                                           &g_status);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  running = false;
  clock.join();
  return result;
}
