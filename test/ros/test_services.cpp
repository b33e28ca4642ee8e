// Services: map_metadata carries `map`'s info and dynamic_map answers `map` itself, ~clear_region
// clears only its box, ~reset empties the map, ~save_map writes the native file and map_server
// images, and a node restarted with map_file publishes the same map. A corrupted map_file and a
// bad parameter stop the node at start-up (exit 1) with a clear message.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <sys/stat.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include "room.h"
#include "run_command.h"
#include "wavog_mapping/ClearRegion.h"
#include "wavog_mapping/SaveMap.h"

namespace {

std::mutex g_mutex;
nav_msgs::OccupancyGrid::ConstPtr g_map;
nav_msgs::OccupancyGrid::ConstPtr g_restored;
nav_msgs::MapMetaData::ConstPtr g_metadata;
ros::Publisher g_scan_pub;

nav_msgs::OccupancyGrid::ConstPtr get(const nav_msgs::OccupancyGrid::ConstPtr& which) {
  std::lock_guard<std::mutex> lock(g_mutex);
  return which;
}

/// The first `map` published after now (the publication timer runs at 5 Hz).
nav_msgs::OccupancyGrid::ConstPtr nextMap(double timeout = 10.0) {
  const ros::Time after = ros::Time::now();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    auto g = get(g_map);
    if (g && g->header.stamp > after) return g;
    ros::WallDuration(0.02).sleep();
  }
  return nullptr;
}

bool exists(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0;
}

/// Asks a node started by room::run() to shut down (it would otherwise run until its timeout).
void stopNode(const std::string& name) {
  std::string ignored;
  room::run("rosnode kill " + name, &ignored);
}

const std::string kDir = "/tmp/wavog_test_services_" + std::to_string(getpid());
const std::string kMapFile = kDir + "/room.wavog";

/// Builds a map of the room from 10 scans of laser_1, then stops publishing.
class Services : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    mkdir(kDir.c_str(), 0755);
    for (int i = 0; i < 10; ++i) {
      g_scan_pub.publish(room::scanOf(room::sensors()[0], ros::Time::now()));
      ros::WallDuration(0.1).sleep();
    }
    ros::WallDuration(0.3).sleep();
  }
};

// First: the map of the set-up's scans, unchanged since (no scan after it).
TEST_F(Services, MapMetadataAndDynamicMapCarryTheMap) {
  const auto map = nextMap();
  ASSERT_TRUE(map);
  ASSERT_GT(room::cellAt(*map, room::kOccX, room::kOccY), 65);
  // map_metadata goes out with every `map`: the latest of each soon carry the same info,
  // map_load_time (the publication's stamp) included.
  nav_msgs::MapMetaData::ConstPtr meta;
  nav_msgs::OccupancyGrid::ConstPtr with;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(10.0);
  while (ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      meta = g_metadata;
      with = g_map;
    }
    if (meta && meta->map_load_time == with->info.map_load_time) break;
    ros::WallDuration(0.01).sleep();
  }
  ASSERT_TRUE(meta) << "nothing on map_metadata";
  EXPECT_EQ(meta->map_load_time, with->info.map_load_time);
  EXPECT_EQ(room::geometry(*meta), room::geometry(with->info));

  // dynamic_map (beside `map`, not private): the map as `map` carries it.
  nav_msgs::GetMap srv;
  ASSERT_TRUE(ros::service::call("dynamic_map", srv));
  const nav_msgs::OccupancyGrid& served = srv.response.map;
  EXPECT_EQ(served.header.frame_id, map->header.frame_id);
  EXPECT_GE(served.header.stamp, map->header.stamp);
  EXPECT_EQ(room::geometry(served.info), room::geometry(map->info));
  EXPECT_TRUE(served.data == map->data) << "dynamic_map differs from map";
}

TEST_F(Services, SaveMapWritesNativeAndMapServerFiles) {
  const auto before = nextMap();
  ASSERT_TRUE(before);
  ASSERT_GT(room::cellAt(*before, room::kOccX, room::kOccY), 65);
  wavog_mapping::SaveMap srv;
  srv.request.path = kMapFile;
  ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_TRUE(exists(kMapFile));
  // wavog_offline's names: <stem>_s<scale>.
  for (const char* s : {"0", "2", "3", "4"}) {
    EXPECT_TRUE(exists(kDir + "/room_s" + s + ".pgm")) << s;
    EXPECT_TRUE(exists(kDir + "/room_s" + s + ".yaml")) << s;
  }
  EXPECT_EQ(srv.response.files.size(), 9u);
  // The PGM is cropped as wavog_offline crops it: the room (7.9 m x 5.9 m at 0.1 m) plus at most
  // two unknown cells a side, not the 6.4 m blocks that hold it.
  {
    std::ifstream pgm(kDir + "/room_s0.pgm", std::ios::binary);
    std::string magic;
    int w = 0, h = 0;
    pgm >> magic >> w >> h;
    EXPECT_EQ(magic, "P5");
    EXPECT_LE(w, 80 + 4);
    EXPECT_LE(h, 60 + 4);
    EXPECT_GE(w, 40);  // what laser_1 sees of the room
    EXPECT_GE(h, 30);
  }

  // The answer says where the files went (issue 41: a relative path goes below map_dir, /tmp
  // here, not the caller's working directory).
  EXPECT_EQ(srv.response.message.rfind("saved 9 files in " + kDir + ": room.wavog room_s0.pgm", 0),
            0u)
      << srv.response.message;
  wavog_mapping::SaveMap relative;
  relative.request.path = kDir.substr(5) + "/rel/room.wavog";  // below map_dir: /tmp
  ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", relative));
  EXPECT_TRUE(relative.response.success) << relative.response.message;
  ASSERT_FALSE(relative.response.files.empty());
  EXPECT_EQ(relative.response.files[0], kDir + "/rel/room.wavog");
  EXPECT_NE(relative.response.message.find(" in " + kDir + "/rel: room.wavog"), std::string::npos)
      << relative.response.message;

  // A missing folder is created.
  wavog_mapping::SaveMap nested;
  nested.request.path = kDir + "/new/sub/room.wavog";
  ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", nested));
  EXPECT_TRUE(nested.response.success) << nested.response.message;
  EXPECT_TRUE(exists(kDir + "/new/sub/room.wavog"));
  EXPECT_TRUE(exists(kDir + "/new/sub/room_s0.pgm"));
  // A folder that cannot be created: a clear refusal.
  wavog_mapping::SaveMap blocked;
  blocked.request.path = kMapFile + "/below_a_file/room.wavog";
  ASSERT_TRUE(ros::service::call("wavog_mapping/save_map", blocked));
  EXPECT_FALSE(blocked.response.success);
  EXPECT_NE(blocked.response.message.find("cannot create the folder"), std::string::npos)
      << blocked.response.message;

  // A node restarted with map_file publishes the same map (same geometry, same values).
  std::string output;
  const std::string cmd =
      std::string("timeout 20 ") + WAVOG_NODE_BIN +
      " __name:=restored map:=/restored/map scan_1:=/restored/scan" +
      " map_metadata:=/restored/map_metadata dynamic_map:=/restored/dynamic_map" +
      " _map_file:=" + kMapFile;
  ros::param::set("/restored/resolution", 0.1);
  ros::param::set("/restored/block_levels", 6);
  std::thread restored([&] { room::run(cmd, &output); });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::WallTime::now() < end && !get(g_restored)) ros::WallDuration(0.05).sleep();
  stopNode("/restored");
  restored.join();
  const auto again = get(g_restored);
  ASSERT_TRUE(again) << output;
  EXPECT_EQ(again->info.width, before->info.width);
  EXPECT_EQ(again->info.height, before->info.height);
  EXPECT_EQ(again->info.resolution, before->info.resolution);
  EXPECT_EQ(again->info.origin.position.x, before->info.origin.position.x);
  EXPECT_EQ(again->info.origin.position.y, before->info.origin.position.y);
  EXPECT_TRUE(again->data == before->data) << "restored map differs";
}

TEST_F(Services, ClearRegionClearsOnlyTheBox) {
  double fx = 0, fy = 0;  // a free cell seen by laser_1
  room::aheadOf(room::sensors()[0], 1.5, &fx, &fy);
  const auto before = nextMap();
  ASSERT_TRUE(before);
  ASSERT_GE(room::cellAt(*before, fx, fy), 0);
  wavog_mapping::ClearRegion srv;
  srv.request.min_x = fx - 0.3;
  srv.request.min_y = fy - 0.3;
  srv.request.max_x = fx + 0.3;
  srv.request.max_y = fy + 0.3;
  ASSERT_TRUE(ros::service::call("wavog_mapping/clear_region", srv));
  EXPECT_TRUE(srv.response.success);
  const auto after = nextMap();
  ASSERT_TRUE(after);
  EXPECT_EQ(room::cellAt(*after, fx, fy), -1);
  // Outside the box nothing changed.
  std::size_t changed_outside = 0;
  for (std::uint32_t iy = 0; iy < after->info.height; ++iy) {
    for (std::uint32_t ix = 0; ix < after->info.width; ++ix) {
      const double x = after->info.origin.position.x + (ix + 0.5) * after->info.resolution;
      const double y = after->info.origin.position.y + (iy + 0.5) * after->info.resolution;
      const bool inside = x >= srv.request.min_x && x <= srv.request.max_x &&
                          y >= srv.request.min_y && y <= srv.request.max_y;
      const std::size_t k = iy * after->info.width + ix;
      if (inside) {
        EXPECT_EQ(after->data[k], -1);
      } else if (after->data[k] != before->data[k]) {
        ++changed_outside;
      }
    }
  }
  EXPECT_EQ(changed_outside, 0u);
  // A box with min > max is refused.
  srv.request.min_x = 1.0;
  srv.request.max_x = 0.0;
  ASSERT_TRUE(ros::service::call("wavog_mapping/clear_region", srv));
  EXPECT_FALSE(srv.response.success);
}

TEST_F(Services, ResetEmptiesTheMap) {
  std_srvs::Empty srv;
  ASSERT_TRUE(ros::service::call("wavog_mapping/reset", srv));
  const auto after = nextMap();
  ASSERT_TRUE(after);
  for (std::int8_t v : after->data) ASSERT_EQ(v, -1);
}

TEST_F(Services, PublishWindowLimitsTheGrid) {
  // A second node on the saved map, publishing only 1 m around base_link (at (0.3, 0.2)).
  ros::param::set("/window/resolution", 0.1);
  ros::param::set("/window/block_levels", 6);
  ros::param::set("/window/publish_rate", 5.0);
  ros::param::set("/window/publish_window", 1.0);
  ros::param::set("/window/map_file", kMapFile);
  nav_msgs::OccupancyGrid::ConstPtr window;
  std::mutex m;
  ros::NodeHandle nh;
  auto sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "window/map", 2,
      boost::function<void(const nav_msgs::OccupancyGrid::ConstPtr&)>(
          [&](const nav_msgs::OccupancyGrid::ConstPtr& g) {
            std::lock_guard<std::mutex> lock(m);
            if (g->info.width > 0) window = g;
          }));
  std::string output;
  std::thread node([&] {
    room::run(std::string("timeout 20 ") + WAVOG_NODE_BIN +
                  " __name:=window map:=/window/map scan:=/window/scan"
                  " map_metadata:=/window/map_metadata dynamic_map:=/window/dynamic_map",
              &output);
  });
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  while (ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(m);
      if (window) break;
    }
    ros::WallDuration(0.05).sleep();
  }
  stopNode("/window");
  node.join();
  std::lock_guard<std::mutex> lock(m);
  ASSERT_TRUE(window) << output;
  // The window clipped to what was observed: inside the window (to the cell), and every border
  // row and column of the grid holds an observed cell. laser_1 sees only the front-left part of
  // the window, so the grid is smaller than the window.
  const nav_msgs::OccupancyGrid& g = *window;
  const double w = g.info.width * g.info.resolution;
  const double h = g.info.height * g.info.resolution;
  const double x0 = g.info.origin.position.x, y0 = g.info.origin.position.y;
  EXPECT_GE(x0, 0.3 - 1.1 - 1e-6);
  EXPECT_GE(y0, 0.2 - 1.1 - 1e-6);
  EXPECT_LE(x0 + w, 0.3 + 1.1 + 1e-6);
  EXPECT_LE(y0 + h, 0.2 + 1.1 + 1e-6);
  EXPECT_LT(w * h, 2.0 * 2.0);
  const auto known = [&g](std::uint32_t x, std::uint32_t y) {
    return g.data[static_cast<std::size_t>(y) * g.info.width + x] != -1;
  };
  bool left = false, right = false, bottom = false, top = false;
  for (std::uint32_t y = 0; y < g.info.height; ++y) {
    left = left || known(0, y);
    right = right || known(g.info.width - 1, y);
  }
  for (std::uint32_t x = 0; x < g.info.width; ++x) {
    bottom = bottom || known(x, 0);
    top = top || known(x, g.info.height - 1);
  }
  EXPECT_TRUE(left && right && bottom && top) << "the grid carries unobserved border lines";
}

TEST_F(Services, DynamicReconfigureValidatesAndApplies) {
  dynamic_reconfigure::Reconfigure srv;
  dynamic_reconfigure::StrParameter scales;
  scales.name = "scales";
  scales.value = "2,5";
  srv.request.config.strs.push_back(scales);
  dynamic_reconfigure::DoubleParameter gamma;
  gamma.name = "gamma";
  gamma.value = 0.5;
  srv.request.config.doubles.push_back(gamma);
  ASSERT_TRUE(ros::service::call("wavog_mapping/set_parameters", srv));
  auto value = [](const dynamic_reconfigure::Config& c, const std::string& name) {
    for (const auto& p : c.strs) {
      if (p.name == name) return p.value;
    }
    for (const auto& p : c.doubles) {
      if (p.name == name) return std::to_string(p.value);
    }
    return std::string("?");
  };
  EXPECT_EQ(value(srv.response.config, "scales"), "2,5");
  EXPECT_EQ(value(srv.response.config, "gamma"), std::to_string(0.5));

  // map_scale_5 now exists. The map is empty since ResetEmptiesTheMap, and a layer is first sent
  // once a cell is observed: advertised, no message yet.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(5.0);
  bool advertised = false;
  while (!advertised && ros::WallTime::now() < end) {
    ros::master::V_TopicInfo topics;
    ASSERT_TRUE(ros::master::getTopics(topics));
    for (const auto& t : topics) {
      advertised =
          advertised || (t.name == "/map_scale_5" && t.datatype == "nav_msgs/OccupancyGrid");
    }
    if (!advertised) ros::WallDuration(0.05).sleep();
  }
  EXPECT_TRUE(advertised) << "map_scale_5 not advertised";
  nav_msgs::OccupancyGrid::ConstPtr g5;
  std::mutex m;
  ros::NodeHandle nh;
  auto sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map_scale_5", 2, &m, &g5);
  ros::WallDuration(1.0).sleep();  // 5 publication periods
  {
    std::lock_guard<std::mutex> lock(m);
    EXPECT_FALSE(g5) << "an empty layer never sent before was published";
  }

  // A refused change fails the call (dynparam exits non-zero: issue 41) and changes nothing: the
  // values in force stay on the parameter server, as the server mirrors them.
  const auto in_force = [](const std::string& name) {
    XmlRpc::XmlRpcValue v;
    if (!ros::param::get("/wavog_mapping/" + name, v)) return std::string("?");
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      return std::to_string(static_cast<double>(v));
    }
    return v.getType() == XmlRpc::XmlRpcValue::TypeString ? static_cast<std::string>(v)
                                                          : std::string("?");
  };
  // A scale beyond block_levels (6) is refused as a whole: the previous values stay.
  dynamic_reconfigure::Reconfigure bad;
  scales.value = "2,9";
  bad.request.config.strs.push_back(scales);
  gamma.value = 0.7;
  bad.request.config.doubles.push_back(gamma);
  EXPECT_FALSE(ros::service::call("wavog_mapping/set_parameters", bad));
  EXPECT_EQ(in_force("scales"), "2,5");
  EXPECT_EQ(in_force("gamma"), std::to_string(0.5));

  // Out of the .cfg range: refused, not clamped to the range (odd_occ must be > 0).
  dynamic_reconfigure::Reconfigure negative;
  dynamic_reconfigure::DoubleParameter odd_occ;
  odd_occ.name = "odd_occ";
  odd_occ.value = -1.0;
  negative.request.config.doubles.push_back(odd_occ);
  gamma.value = 0.9;
  negative.request.config.doubles.push_back(gamma);
  EXPECT_FALSE(ros::service::call("wavog_mapping/set_parameters", negative));
  EXPECT_EQ(in_force("odd_occ"), std::to_string(3.5));
  EXPECT_EQ(in_force("gamma"), std::to_string(0.5));
  // An unknown policy name: refused.
  dynamic_reconfigure::Reconfigure policy;
  dynamic_reconfigure::StrParameter name;
  name.name = "policy";
  name.value = "forgett";
  policy.request.config.strs.push_back(name);
  EXPECT_FALSE(ros::service::call("wavog_mapping/set_parameters", policy));
  EXPECT_EQ(in_force("policy"), "forget");
}

TEST_F(Services, SilentLaserIsReportedStale) {
  // No scan since the suite's set-up: /diagnostics must say so (a planner must know).
  std::mutex m;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> d;
  ros::NodeHandle nh;
  auto sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10,
      boost::function<void(const diagnostic_msgs::DiagnosticArray::ConstPtr&)>(
          [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
            std::lock_guard<std::mutex> lock(m);
            for (const auto& st : a->status) d[st.name] = st;
          }));
  const auto find = [&](const std::string& part) {
    std::lock_guard<std::mutex> lock(m);
    for (const auto& kv : d) {
      if (kv.first.find(part) != std::string::npos) return kv.second;
    }
    return diagnostic_msgs::DiagnosticStatus();
  };
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(15.0);
  while (ros::WallTime::now() < end) {
    if (find("/scan_1 input").message.find("stale") != std::string::npos &&
        find("/scan_1 rate").level == diagnostic_msgs::DiagnosticStatus::ERROR) {
      break;
    }
    ros::WallDuration(0.1).sleep();
  }
  const auto input = find("/scan_1 input");
  EXPECT_EQ(input.level, diagnostic_msgs::DiagnosticStatus::WARN) << input.message;
  EXPECT_NE(input.message.find("stale"), std::string::npos) << input.message;
  const auto rate = find("/scan_1 rate");
  EXPECT_EQ(rate.level, diagnostic_msgs::DiagnosticStatus::ERROR) << rate.message;
}

TEST_F(Services, CorruptedMapFileFailsAtStartUp) {
  const std::string bad = kDir + "/corrupt.wavog";
  {
    std::ifstream in(kMapFile, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 64u);
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x5a);
    std::ofstream out(bad, std::ios::binary);
    out << bytes;
  }
  ros::param::set("/corrupt/resolution", 0.1);
  ros::param::set("/corrupt/block_levels", 6);
  std::string output;
  const int code = room::run(std::string("timeout 8 ") + WAVOG_NODE_BIN +
                                 " __name:=corrupt map:=/corrupt/map _map_file:=" + bad,
                             &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("map_file"), std::string::npos) << output;
  EXPECT_NE(output.find(bad), std::string::npos) << output;
}

TEST_F(Services, BadParameterFailsAtStartUpNamingIt) {
  std::string output;
  const int code = room::run(std::string("timeout 8 ") + WAVOG_NODE_BIN +
                                 " __name:=badparam map:=/badparam/map _publish_rate:=-2.0",
                             &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("publish_rate (-2) must be in (0, 100] Hz"), std::string::npos) << output;
}

// Issue 41, item 6: `scan` and `/scan` in the root namespace are one topic: refused at start-up
// naming inputs (every scan was integrated twice).
TEST_F(Services, InputsThatAreOneTopicAreRefusedAtStartUp) {
  XmlRpc::XmlRpcValue inputs;
  inputs[0] = std::string("scan");
  inputs[1] = std::string("/scan");
  ros::param::set("/dup_inputs/inputs", inputs);
  std::string output;
  const int code = room::run(
      std::string("timeout 8 ") + WAVOG_NODE_BIN + " __name:=dup_inputs map:=/dup_inputs/map",
      &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("inputs[0].topic ('scan') and inputs[1].topic ('/scan') are one topic, "
                        "/scan"),
            std::string::npos)
      << output;
}

// Issue 41, item 2: an input nothing publishes is warned on the console with the LaserScan
// topics that exist (this test advertises /scan_1); /diagnostics alone said "no scan yet".
TEST_F(Services, AnInputWithoutPublisherNamesTheLaserScanTopics) {
  std::string output;
  room::run(std::string("timeout 14 ") + WAVOG_NODE_BIN + " __ns:=/silent __name:=wavog_mapping",
            &output);
  EXPECT_NE(output.find("no scan received on /silent/scan: nothing publishes it. LaserScan "
                        "topics advertised: "),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("/scan_1"), std::string::npos) << output;
}

TEST_F(Services, NodeletWithBadParameterFailsToLoadNamingIt) {
  std::string output;
  const int code = room::run("timeout 8 " + std::string(WAVOG_NODELET_BIN) +
                                 " standalone wavog_mapping/MappingNodelet __name:=badnodelet"
                                 " map:=/badnodelet/map _queue_size:=0",
                             &output);
  EXPECT_NE(code, 0) << output;
  EXPECT_NE(code, 124) << "timed out instead of failing: " << output;
  EXPECT_NE(output.find("queue_size (0) must be in [1, 1000]"), std::string::npos) << output;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_services");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  g_scan_pub = nh.advertise<sensor_msgs::LaserScan>("scan_1", 50);
  auto map_sub = room::keepLatest<nav_msgs::OccupancyGrid>(nh, "map", 2, &g_mutex, &g_map);
  auto meta_sub =
      room::keepLatest<nav_msgs::MapMetaData>(nh, "map_metadata", 2, &g_mutex, &g_metadata);
  auto restored_sub = nh.subscribe<nav_msgs::OccupancyGrid>(
      "restored/map", 2,
      boost::function<void(const nav_msgs::OccupancyGrid::ConstPtr&)>(
          [](const nav_msgs::OccupancyGrid::ConstPtr& g) {
            std::lock_guard<std::mutex> lock(g_mutex);
            if (!g_restored) g_restored = g;
          }));
  ros::AsyncSpinner spinner(2);
  spinner.start();
  room::waitForSubscribers(g_scan_pub, 1, 20.0);
  ros::service::waitForService("wavog_mapping/reset", ros::Duration(20));
  const int result = RUN_ALL_TESTS();
  std::string ignored;
  room::run("rm -rf " + kDir, &ignored);
  return result;
}
