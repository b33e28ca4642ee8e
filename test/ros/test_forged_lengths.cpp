// Forged array lengths over ROS (test/forged_lengths.test, issue 42): the mapper node and
// wavog_fleet each get well-formed messages whose one array length prefix is rewritten to claim
// 1e8 and 2^32 - 1 elements (LaserScan ranges and intensities, PlacedScan ranges and range_codes),
// sent as raw bytes on the real topic types. Each is counted as dropped_bad_length (received too;
// the fleet's index still steps: nothing counted lost), a good message after them is integrated,
// and the node's peak resident memory (VmHWM) grows by less than kMaxGrowthMiB: roscpp alone sized
// the arrays before the check, 1e8 float ranges making the mapper allocate and zero 381 MiB.
#include <gtest/gtest.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <xmlrpcpp/XmlRpc.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "wavog_mapping/FleetStatus.h"
#include "wavog_mapping/MapperStatus.h"
#include "wavog_mapping/PlacedScan.h"

namespace forged {

/// Raw bytes published as message type Like (its md5sum, datatype and definition).
template <typename Like>
struct Bytes {
  std::vector<std::uint8_t> data;
};

}  // namespace forged

namespace ros {
namespace message_traits {
template <typename Like>
struct MD5Sum<forged::Bytes<Like>> {
  static const char* value() { return MD5Sum<Like>::value(); }
  static const char* value(const forged::Bytes<Like>&) { return value(); }
};
template <typename Like>
struct DataType<forged::Bytes<Like>> {
  static const char* value() { return DataType<Like>::value(); }
  static const char* value(const forged::Bytes<Like>&) { return value(); }
};
template <typename Like>
struct Definition<forged::Bytes<Like>> {
  static const char* value() { return Definition<Like>::value(); }
  static const char* value(const forged::Bytes<Like>&) { return value(); }
};
}  // namespace message_traits
namespace serialization {
template <typename Like>
struct Serializer<forged::Bytes<Like>> {
  template <typename Stream>
  static void write(Stream& stream, const forged::Bytes<Like>& m) {
    if (!m.data.empty()) {
      std::memcpy(stream.advance(static_cast<std::uint32_t>(m.data.size())), m.data.data(),
                  m.data.size());
    }
  }
  static std::uint32_t serializedLength(const forged::Bytes<Like>& m) {
    return static_cast<std::uint32_t>(m.data.size());
  }
};
}  // namespace serialization
}  // namespace ros

namespace {

constexpr double kMaxGrowthMiB = 16.0;  // of VmHWM over all forged messages
constexpr double kWaitSeconds = 20.0;

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_mapper;
wavog_mapping::FleetStatus::ConstPtr g_fleet;

template <typename M>
std::vector<std::uint8_t> bytesOf(const M& m) {
  std::vector<std::uint8_t> b(ros::serialization::serializationLength(m));
  ros::serialization::OStream out(b.data(), static_cast<std::uint32_t>(b.size()));
  ros::serialization::serialize(out, m);
  return b;
}

/// The node's pid through its XML-RPC getPid; -1 if it cannot be asked.
int nodePid(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, true)) return -1;
  std::string host;
  std::uint32_t port = 0;
  if (!ros::network::splitURI(static_cast<std::string>(payload), host, port)) return -1;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue a, r;
  a[0] = ros::this_node::getName();
  if (!client.execute("getPid", a, r) || r.getType() != XmlRpc::XmlRpcValue::TypeArray) return -1;
  return static_cast<int>(r[2]);
}

/// Peak resident memory (VmHWM) of process `pid` in MiB; NaN if unreadable.
double peakRssMiB(int pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream s(line.substr(6));
      double kb = 0.0;
      s >> kb;
      return kb / 1024.0;
    }
  }
  return std::nan("");
}

bool waitFor(const std::function<bool()>& done) {
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(kWaitSeconds);
  while (ros::ok() && ros::WallTime::now() < give_up) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (done()) return true;
    }
    ros::WallDuration(0.05).sleep();
  }
  return false;
}

sensor_msgs::LaserScan goodScan(std::uint32_t seq) {
  sensor_msgs::LaserScan s;
  s.header.seq = seq;
  s.header.stamp = ros::Time::now();
  s.header.frame_id = "laser";  // the map frame: placed without tf
  s.angle_min = -M_PI;
  s.angle_increment = 2.0 * M_PI / 360.0;
  s.angle_max = s.angle_min + 359 * s.angle_increment;
  s.range_min = 0.1f;
  s.range_max = 20.0f;
  s.ranges.assign(360, 2.0f);
  s.intensities.assign(360, 1.0f);
  return s;
}

wavog_mapping::PlacedScan goodPlaced(std::uint64_t index) {
  wavog_mapping::PlacedScan m;
  m.version = wavog_mapping::PlacedScan::VERSION_FLOAT32;
  m.header.stamp = ros::Time::now();
  m.header.frame_id = "map";
  m.vehicle = "v1";
  m.input = "scan";
  m.index = index;
  m.angle_min = -M_PI;
  m.angle_increment = 2.0 * M_PI / 360.0;
  m.range_min = 0.1;
  m.range_max = 20.0;
  m.ranges.assign(360, 2.0f);
  return m;
}

std::vector<std::uint32_t> prefixes() {
  ros::NodeHandle pnh("~");
  std::string text = "100000000 4294967295";
  int one = 0;
  if (!pnh.getParam("prefixes", text) && pnh.getParam("prefixes", one)) text = std::to_string(one);
  std::istringstream in(text);
  std::vector<std::uint32_t> out;
  std::uint64_t v = 0;
  while (in >> v) out.push_back(static_cast<std::uint32_t>(v));
  return out;
}

void onMapperStatus(const wavog_mapping::MapperStatus::ConstPtr& s) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_mapper = s;
}

void onFleetStatus(const wavog_mapping::FleetStatus::ConstPtr& s) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_fleet = s;
}

void setPrefix(std::vector<std::uint8_t>* b, std::size_t at, std::uint32_t n) {
  std::memcpy(b->data() + at, &n, 4);
}

TEST(ForgedLengths, RefusedCountedAndNothingAllocated) {
  ros::NodeHandle nh;
  ros::Subscriber ms = nh.subscribe("/wavog_mapping/status", 10, onMapperStatus);
  ros::Subscriber fs = nh.subscribe("/wavog_fleet/fleet_status", 10, onFleetStatus);
  ros::Publisher scan_raw = nh.advertise<forged::Bytes<sensor_msgs::LaserScan>>("/scan", 10);
  ros::Publisher scan_good = nh.advertise<sensor_msgs::LaserScan>("/scan", 10);
  ros::Publisher placed_raw =
      nh.advertise<forged::Bytes<wavog_mapping::PlacedScan>>("/v1/fleet_scans", 10);
  ros::Publisher placed_good = nh.advertise<wavog_mapping::PlacedScan>("/v1/fleet_scans", 10);
  ASSERT_TRUE(waitFor([&] {
    return scan_raw.getNumSubscribers() > 0 && scan_good.getNumSubscribers() > 0 &&
           placed_raw.getNumSubscribers() > 0 && placed_good.getNumSubscribers() > 0;
  })) << "the nodes never subscribed";
  const int mapper_pid = nodePid("/wavog_mapping");
  const int fleet_pid = nodePid("/wavog_fleet");
  ASSERT_GT(mapper_pid, 0);
  ASSERT_GT(fleet_pid, 0);

  // One good message each first (the nodes' working memory), then the forged ones.
  std::uint32_t seq = 1;
  std::uint64_t index = 0;
  scan_good.publish(goodScan(seq++));
  placed_good.publish(goodPlaced(index++));
  // Not fatal: the peak memory below is still measured and printed.
  EXPECT_TRUE(waitFor([] {
    return g_mapper && !g_mapper->inputs.empty() && g_mapper->inputs[0].integrated >= 1 &&
           g_fleet && !g_fleet->vehicles.empty() && g_fleet->vehicles[0].integrated >= 1;
  })) << "the good messages were not integrated";
  ros::WallDuration(0.5).sleep();
  const double mapper_before = peakRssMiB(mapper_pid);
  const double fleet_before = peakRssMiB(fleet_pid);

  const std::vector<std::uint32_t> claims = prefixes();
  std::uint64_t forged_scans = 0;
  std::uint64_t forged_placed = 0;
  for (std::uint32_t n : claims) {
    const sensor_msgs::LaserScan s = goodScan(0);
    const std::size_t ranges_at = 4 + 8 + 4 + s.header.frame_id.size() + 7 * 4;
    const std::size_t intensities_at = ranges_at + 4 + 4 * s.ranges.size();
    for (std::size_t at : {ranges_at, intensities_at}) {
      forged::Bytes<sensor_msgs::LaserScan> f;
      f.data = bytesOf(goodScan(seq++));
      setPrefix(&f.data, at, n);
      scan_raw.publish(f);
      ++forged_scans;
    }
    for (bool codes_array : {false, true}) {
      const wavog_mapping::PlacedScan p = goodPlaced(index++);
      forged::Bytes<wavog_mapping::PlacedScan> f;
      f.data = bytesOf(p);
      // ranges (4 + 4 x 360 bytes), then range_codes (4, empty), then range_step (8).
      const std::size_t codes_at = f.data.size() - 8 - 4;
      setPrefix(&f.data, codes_array ? codes_at : codes_at - 4 - 4 * p.ranges.size(), n);
      placed_raw.publish(f);
      ++forged_placed;
    }
    ros::WallDuration(0.2).sleep();
  }
  // A good message after them: the nodes go on, nothing counted lost.
  scan_good.publish(goodScan(seq++));
  placed_good.publish(goodPlaced(index++));
  const bool counted = waitFor([&] {
    return g_mapper && !g_mapper->inputs.empty() && g_mapper->inputs[0].integrated >= 2 &&
           g_mapper->inputs[0].dropped_bad_length == forged_scans && g_fleet &&
           !g_fleet->vehicles.empty() && g_fleet->vehicles[0].integrated >= 2 &&
           g_fleet->vehicles[0].dropped_bad_length == forged_placed;
  });
  ros::WallDuration(0.5).sleep();
  const double mapper_after = peakRssMiB(mapper_pid);
  const double fleet_after = peakRssMiB(fleet_pid);
  std::ostringstream claims_text;
  for (std::uint32_t n : claims) claims_text << " " << n;
  std::cout << "forged lengths (" << claims_text.str() << " ): mapper VmHWM " << mapper_before
            << " -> " << mapper_after << " MiB, wavog_fleet VmHWM " << fleet_before << " -> "
            << fleet_after << " MiB\n";
  RecordProperty("mapper_vmhwm_growth_kib",
                 static_cast<int>((mapper_after - mapper_before) * 1024));
  RecordProperty("fleet_vmhwm_growth_kib", static_cast<int>((fleet_after - fleet_before) * 1024));
  std::lock_guard<std::mutex> lock(g_mutex);
  ASSERT_TRUE(counted && g_mapper && g_fleet)
      << "the forged messages were not all counted as bad_length, or a good message not "
         "integrated after them";
  const wavog_mapping::InputStatus& in = g_mapper->inputs[0];
  EXPECT_EQ(in.received, 2 + forged_scans);
  EXPECT_EQ(in.lost, 0u);
  EXPECT_EQ(in.dropped_exception, 0u);
  EXPECT_EQ(g_mapper->exceptions, 0u);
  const wavog_mapping::VehicleStatus& v = g_fleet->vehicles[0];
  EXPECT_EQ(v.received, 2 + forged_placed);
  EXPECT_EQ(v.lost, 0u);  // the forged messages' indices were read: delivered, not lost
  EXPECT_EQ(v.index_regressions, 0u);
  EXPECT_LT(mapper_after - mapper_before, kMaxGrowthMiB);
  EXPECT_LT(fleet_after - fleet_before, kMaxGrowthMiB);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_forged_lengths");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  return RUN_ALL_TESTS();
}
