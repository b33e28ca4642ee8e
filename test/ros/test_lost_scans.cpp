// Lost scans (lost_scans.test): every scan published into the node is integrated or counted.
// - gaps in header.seq are counted as `lost`, exactly, and only on that input;
// - a publisher whose seq is always 0 produces no count;
// - a burst of 500 scans published as fast as possible: the node with the default subscriber
//   queue integrates all of them; the node whose subscriber queue holds one scan loses some, and
//   integrated + every drop counter + lost == 500.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cstdint>
#include <mutex>
#include <sstream>

#include "room.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr int kBurst = 500;
constexpr int kLeadIn = 10;

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;       // wavog_mapping: default subscriber queue
wavog_mapping::MapperStatus::ConstPtr g_tiny_status;  // tiny/wavog_mapping: a queue of 1
ros::Publisher g_pub[3];

/// Every drop counter of an input.
std::uint64_t dropped(const wavog_mapping::InputStatus& in) {
  return in.dropped_empty + in.dropped_bad_angles +
         in.dropped_bad_frame + in.dropped_tf_unavailable + in.dropped_tf_too_old +
         in.dropped_no_valid_beam + in.dropped_bad_geometry + in.dropped_out_of_extent +
         in.dropped_absurd_pose + in.dropped_bad_time + in.dropped_exception;
}

/// Scans of the input accounted for: integrated, dropped for a reason, or lost before receipt.
std::uint64_t accounted(const wavog_mapping::InputStatus& in) {
  return in.integrated + dropped(in) + in.lost;
}

std::string describe(const wavog_mapping::InputStatus& in) {
  std::ostringstream os;
  os << in.topic << ": received " << in.received << ", integrated " << in.integrated
     << ", dropped " << dropped(in) << ", lost " << in.lost;
  return os.str();
}

/// Waits until input `i` of the status in *status satisfies `pred`; returns that input (or the
/// last seen at the timeout; an empty one when no status came).
template <typename Pred>
wavog_mapping::InputStatus waitInput(const wavog_mapping::MapperStatus::ConstPtr* status,
                                     std::size_t i, Pred pred, double timeout) {
  const auto s = room::waitLatest(
      &g_mutex, status,
      [&](const wavog_mapping::MapperStatus& m) { return m.inputs.size() > i && pred(m.inputs[i]); },
      timeout);
  return s && s->inputs.size() > i ? s->inputs[i] : wavog_mapping::InputStatus();
}

/// A scan of laser `sensor` with header.seq `seq`.
sensor_msgs::LaserScan::Ptr scan(int sensor, std::uint32_t seq) {
  auto s = room::scanOf(room::sensors()[static_cast<std::size_t>(sensor)], ros::Time::now());
  s->header.seq = seq;
  return s;
}

TEST(LostScans, SeqGapsAreCountedExactly) {
  // seq 1..10, then 14..20: 11, 12 and 13 never published, as if a queue had dropped them.
  int published = 0;
  for (std::uint32_t seq = 1; seq <= 20; ++seq) {
    if (seq >= 11 && seq <= 13) continue;
    g_pub[0].publish(scan(0, seq));
    ++published;
    ros::WallDuration(0.03).sleep();
  }
  const auto in = waitInput(
      &g_status, 0, [&](const auto& i) { return i.integrated >= static_cast<unsigned>(published); },
      30.0);
  EXPECT_EQ(in.received, static_cast<std::uint64_t>(published)) << describe(in);
  EXPECT_EQ(in.integrated, static_cast<std::uint64_t>(published)) << describe(in);
  EXPECT_EQ(in.lost, 3u) << describe(in);
}

TEST(LostScans, SeqAlwaysZeroIsNotCounted) {
  for (int i = 0; i < 20; ++i) {
    g_pub[1].publish(scan(1, 0));
    ros::WallDuration(0.03).sleep();
  }
  const auto in =
      waitInput(&g_status, 1, [](const auto& i) { return i.integrated >= 20u; }, 30.0);
  EXPECT_EQ(in.received, 20u) << describe(in);
  EXPECT_EQ(in.integrated, 20u) << describe(in);
  EXPECT_EQ(in.lost, 0u) << describe(in);
  // And the gaps of the other input stayed there.
  const auto other = waitInput(&g_status, 0, [](const auto&) { return true; }, 5.0);
  EXPECT_EQ(other.lost, 3u) << describe(other);
}

TEST(LostScans, EveryScanOfABurstIsIntegratedOrCounted) {
  // A paced lead-in first: the counter trusts seq once it has increased by 1 (a publisher whose
  // seq means nothing must not produce counts), so a loss before that would not be counted.
  // Closed loop: each lead-in scan is published once both nodes have received the one before,
  // so that even a slow node (a sanitizer build) never holds two in its queue of one.
  for (int i = 0; i < kLeadIn; ++i) {
    g_pub[2].publish(scan(2, static_cast<std::uint32_t>(i + 1)));
    const auto got = [i](const wavog_mapping::InputStatus& in) {
      return in.received >= static_cast<std::uint64_t>(i + 1);
    };
    ASSERT_EQ(waitInput(&g_status, 2, got, 30.0).received, static_cast<unsigned>(i + 1));
    ASSERT_EQ(waitInput(&g_tiny_status, 0, got, 30.0).received, static_cast<unsigned>(i + 1));
  }
  // Then the burst, as fast as possible (the publisher's own queue holds all of it).
  for (int i = kLeadIn; i < kLeadIn + kBurst; ++i) {
    g_pub[2].publish(scan(2, static_cast<std::uint32_t>(i + 1)));
  }
  constexpr auto kPublished = static_cast<std::uint64_t>(kLeadIn + kBurst);
  const auto all = [](const wavog_mapping::InputStatus& i) { return accounted(i) >= kPublished; };
  // The default subscriber queue holds the whole burst: nothing is lost, everything integrated.
  const auto big = waitInput(&g_status, 2, all, 60.0);
  EXPECT_EQ(big.lost, 0u) << describe(big);
  EXPECT_EQ(big.received, kPublished) << describe(big);
  EXPECT_EQ(big.integrated, kPublished) << describe(big);
  // A queue of one scan overflows; each scan it dropped is counted from the seq gaps (the last
  // scan of the burst is always received, so every gap lies between two received scans).
  const auto tiny = waitInput(&g_tiny_status, 0, all, 60.0);
  EXPECT_EQ(accounted(tiny), kPublished) << describe(tiny);
  EXPECT_EQ(tiny.received + tiny.lost, kPublished) << describe(tiny);
  EXPECT_GT(tiny.lost, 0u) << "a subscriber queue of 1 held a burst of " << kBurst
                           << " scans: the test no longer overflows it; " << describe(tiny);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_lost_scans");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  // roscpp writes its own count into header.seq of what it sends over TCP; a publisher that
  // declares no header keeps the message's seq, as rosbag play keeps the recorded one.
  for (int i = 0; i < 3; ++i) {
    auto opts = ros::AdvertiseOptions::create<sensor_msgs::LaserScan>(
        "scan_" + std::to_string(i + 1), 2 * kBurst, ros::SubscriberStatusCallback(),
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), nullptr);
    opts.has_header = false;
    g_pub[i] = nh.advertise(opts);
  }
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  auto tiny_sub = room::keepLatest<wavog_mapping::MapperStatus>(
      nh, "tiny/wavog_mapping/status", 10, &g_mutex, &g_tiny_status);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  room::waitForSubscribers(g_pub[0], 1, 20.0);
  room::waitForSubscribers(g_pub[1], 1, 20.0);
  room::waitForSubscribers(g_pub[2], 2, 20.0);  // both nodes
  // Both nodes hold the static tree before the first scan (else scans wait for tf and the burst
  // would test the tf filter's queue instead).
  room::waitLatest(&g_mutex, &g_status, [](const auto&) { return true; }, 20.0);
  room::waitLatest(&g_mutex, &g_tiny_status, [](const auto&) { return true; }, 20.0);
  ros::WallDuration(0.5).sleep();
  return RUN_ALL_TESTS();
}
