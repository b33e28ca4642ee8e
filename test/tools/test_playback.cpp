// Playback rostest (playback.test): waits until the node has integrated every scan of the played
// bag, saves its map through ~save_map, runs wavog_offline on the same bag with the same YAML and
// checks that the finest maps agree: the same observed cells and the same occupied cells, except
// the few that depend on the tf interpolation. A scan the node did not integrate fails the test
// before the comparison, by where it went (never received, counted lost, dropped, still waiting).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <unistd.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>

#include "wavog_mapping/MapperStatus.h"
#include "wavog_mapping/SaveMap.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"

namespace {

namespace fs = std::filesystem;

constexpr double kWaitSeconds = 120.0;        // wall time for the node to integrate the scans
constexpr double kOccupiedProb = 0.65;        // a cell is occupied above this P(occ) (map_server's)
constexpr double kMaxDisagreement = 0.01;     // of the occupied cells
constexpr double kSettleSeconds = 3.0;        // no new integration for this long: the node is done
constexpr double kQuietSeconds = 15.0;        // no counter moved for this long: nothing is coming

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;

/// Scans of the input dropped for any reason.
std::uint64_t droppedScans(const wavog_mapping::InputStatus& in) {
  return in.dropped_empty + in.dropped_bad_angles +
         in.dropped_bad_frame + in.dropped_tf_unavailable + in.dropped_tf_too_old +
         in.dropped_no_valid_beam + in.dropped_bad_geometry + in.dropped_out_of_extent +
         in.dropped_absurd_pose + in.dropped_bad_time + in.dropped_exception;
}

void onStatus(const wavog_mapping::MapperStatus::ConstPtr& s) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_status = s;
}

TEST(Playback, NodeMapAgreesWithOfflineMap) {
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::string bag;
  std::string config;
  int scans = 0;
  ASSERT_TRUE(pnh.getParam("bag", bag));
  ASSERT_TRUE(pnh.getParam("config", config));
  ASSERT_TRUE(pnh.getParam("scans", scans));
  const fs::path dir = fs::temp_directory_path() / ("wavog_playback_" + std::to_string(::getpid()));
  fs::create_directories(dir);

  // The offline map first (it does not need the node), while the bag plays.
  const std::string cmd = std::string(WAVOG_OFFLINE) + " --quiet -c " + config + " -o " +
                          (dir / "offline").string() + " " + bag;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  ros::Subscriber sub = nh.subscribe("/wavog_mapping/status", 10, onStatus);
  const ros::WallTime started = ros::WallTime::now();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kWaitSeconds);
  // Wait for every scan to be handled, or for the counts to settle once every scan was received
  // or counted lost (the bag's tail keeps rosbag play, and so this test, alive for a while after
  // the last scan), or for a long quiet time (scans lost without a count never arrive).
  std::uint64_t integrated = 0;
  std::uint64_t received = 0;
  ros::WallTime last_change = ros::WallTime::now();
  wavog_mapping::InputStatus input;
  const auto n = static_cast<std::uint64_t>(scans);
  while (ros::ok() && ros::WallTime::now() < deadline) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_status && !g_status->inputs.empty()) {
        const wavog_mapping::InputStatus& latest = g_status->inputs[0];
        if (latest.integrated != input.integrated || latest.received != input.received ||
            latest.lost != input.lost || droppedScans(latest) != droppedScans(input)) {
          last_change = ros::WallTime::now();
        }
        input = latest;
        integrated = input.integrated;
        received = input.received;
      }
    }
    const double quiet = (ros::WallTime::now() - last_change).toSec();
    if (integrated + droppedScans(input) >= n) break;
    if (received + input.lost >= n && quiet > kSettleSeconds) break;
    if (received > 0 && quiet > kQuietSeconds) break;
    ros::WallDuration(0.05).sleep();
  }
  const double waited = (ros::WallTime::now() - started).toSec();
  RecordProperty("node_received", static_cast<int>(received));
  RecordProperty("node_integrated", static_cast<int>(integrated));
  RecordProperty("node_lost", static_cast<int>(input.lost));
  // Every scan of the bag must be integrated before the maps are compared: a scan that is missing
  // is named here, by where it went, instead of showing up as cells that differ.
  const std::uint64_t dropped = droppedScans(input);
  ASSERT_TRUE(received <= n && input.lost <= n - received)
      << "the node received " << received << " and counted " << input.lost << " lost of " << n
      << " scans: the bag holds more than " << n << "?\n" << input;
  ASSERT_EQ(received, n) << n - received << " of " << n
                         << " scans never reached the node's callback, most likely dropped by its "
                            "full subscriber queue (subscriber_queue_size): "
                         << input.lost << " of them counted as lost (header.seq gaps), "
                         << n - received - input.lost
                         << " not counted (header.seq of this bag does not increase by 1); maps "
                            "not compared. Last status of the input:\n"
                         << input;
  ASSERT_EQ(dropped, 0u) << dropped << " of " << n
                         << " scans dropped by the node (see the counters); maps not compared:\n"
                         << input;
  // None may wait in the tf filter forever (the node feeds tf to its buffer itself, serialised
  // with the filter, to avoid the tf2_ros 0.7 MessageFilter race).
  ASSERT_EQ(integrated, n) << n - integrated << " of " << n
                           << " scans received but neither integrated nor dropped (still "
                              "waiting for tf); maps not compared:\n"
                           << input;

  ros::ServiceClient save = nh.serviceClient<wavog_mapping::SaveMap>("/wavog_mapping/save_map");
  ASSERT_TRUE(save.waitForExistence(ros::Duration(10.0)));
  wavog_mapping::SaveMap srv;
  srv.request.path = (dir / "node.wavog").string();
  ASSERT_TRUE(save.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;

  const wavog::MapParams params = wavog_ros::loadConfigFile(config, nullptr).map;
  wavog::WaveletMap node(params);
  wavog::WaveletMap offline(params);
  node.load(srv.request.path);
  offline.load((dir / "offline" / "map.wavog").string());

  wavog::CellBox a;
  wavog::CellBox b;
  ASSERT_TRUE(node.bounds(0, &a));
  ASSERT_TRUE(offline.bounds(0, &b));
  const wavog::CellBox box{std::min(a.min_x, b.min_x), std::min(a.min_y, b.min_y),
                           std::max(a.max_x, b.max_x), std::max(a.max_y, b.max_y)};
  const wavog::Raster rn = node.exportScale(0, box, wavog::Aggregation::kMean);
  const wavog::Raster ro = offline.exportScale(0, box, wavog::Aggregation::kMean);
  const float occ = static_cast<float>(std::log(kOccupiedProb / (1.0 - kOccupiedProb)));
  std::size_t occupied = 0;
  std::size_t occupied_diff = 0;
  std::size_t known_diff = 0;
  std::size_t observed = 0;
  for (std::size_t i = 0; i < rn.log_odds.size(); ++i) {
    const bool on = rn.known[i] && rn.log_odds[i] > occ;
    const bool oo = ro.known[i] && ro.log_odds[i] > occ;
    occupied += oo ? 1 : 0;
    occupied_diff += on != oo ? 1 : 0;
    known_diff += rn.known[i] != ro.known[i] ? 1 : 0;
    observed += ro.known[i] ? 1 : 0;
  }
  std::cout << "playback: node vs offline: " << occupied << " occupied cells, " << occupied_diff
            << " differ; " << observed << " observed cells, " << known_diff << " differ\n";
  RecordProperty("occupied_cells", static_cast<int>(occupied));
  RecordProperty("occupied_differ", static_cast<int>(occupied_diff));
  RecordProperty("observed_cells", static_cast<int>(observed));
  RecordProperty("observed_differ", static_cast<int>(known_diff));
  RecordProperty("wait_for_node_s", std::to_string(waited));
  EXPECT_GT(occupied, 1000u);
  EXPECT_LE(static_cast<double>(occupied_diff), kMaxDisagreement * static_cast<double>(occupied));
  EXPECT_LE(static_cast<double>(known_diff), kMaxDisagreement * static_cast<double>(observed));
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_playback");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
