// The NDT layers of the node (ndt: true): `ndt_markers` (MarkerArray, latched) and `ndt_cells`
// (PointCloud2, latched) for the finest scale, ndt_markers_scale_<s> / ndt_cells_scale_<s> while
// subscribed. The four lasers see the room for 1 s: every Gaussian holds beam end-points, so its
// mean lies on a wall (within a cell at the corners), its ellipse runs along the wall, and it is
// drawn red (occupied). A node with forget_half_life: 60 keeps at least the same Gaussians from
// the same scans (issue 38: before, its end-points weighed 0.001 and fell under ndt_min_weight).
// A node with ndt: false advertises none of these topics, a bad ndt_min_weight stops the node at
// start-up naming the parameter, and a floor that keeps no Gaussian is warned about.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "room.h"
#include "run_command.h"
#include "wavog_mapping/MapperStatus.h"

namespace {

constexpr int kScansPerLaser = 10;
constexpr double kResolution = 0.1;  // test/ros/room.yaml
const std::vector<std::string> kFields = {"x",      "y",      "z",      "cov_xx",
                                          "cov_xy", "cov_yy", "weight", "occupancy"};

std::mutex g_mutex;
wavog_mapping::MapperStatus::ConstPtr g_status;
visualization_msgs::MarkerArray::ConstPtr g_markers, g_markers_2;
sensor_msgs::PointCloud2::ConstPtr g_cells, g_cells_2;
wavog_mapping::MapperStatus::ConstPtr g_half_life_status;  // the forget_half_life: 60 node's
sensor_msgs::PointCloud2::ConstPtr g_half_life_cells;

/// Distance from (x, y) inside the room to its nearest wall.
double wallDistance(double x, double y) {
  return std::min(std::abs(room::kHalfX - std::abs(x)), std::abs(room::kHalfY - std::abs(y)));
}

template <typename M>
boost::shared_ptr<const M> fresh(const boost::shared_ptr<const M>* which) {
  return room::waitLatest(
      &g_mutex, which, [](const M&) { return true; }, 10.0);
}

/// The x, y, weight of a cloud's points, in its order.
struct CloudPoint {
  float x, y, w;
};
std::vector<CloudPoint> pointsOf(const sensor_msgs::PointCloud2& cloud) {
  std::vector<CloudPoint> out;
  sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x"), y(cloud, "y"), w(cloud, "weight");
  for (; x != x.end(); ++x, ++y, ++w) out.push_back({*x, *y, *w});
  return out;
}

/// Checks a MarkerArray of one scale (cell size `cell`) against the room; at the finest scale a
/// cell of end-points is occupied (red). A coarse cell averages the wall with free cells.
void checkMarkers(const visualization_msgs::MarkerArray& msg, int scale, double cell) {
  ASSERT_GE(msg.markers.size(), 2u) << "a DELETEALL and at least one ellipse";
  EXPECT_EQ(msg.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const std::string ns = "ndt_scale_" + std::to_string(scale);
  std::size_t on_wall = 0, red = 0, long_along_x_wall = 0, across_x_wall = 0;
  for (std::size_t i = 1; i < msg.markers.size(); ++i) {
    const visualization_msgs::Marker& m = msg.markers[i];
    EXPECT_EQ(m.action, visualization_msgs::Marker::ADD);
    EXPECT_EQ(m.type, visualization_msgs::Marker::CYLINDER);
    EXPECT_EQ(m.ns, ns);
    EXPECT_EQ(m.header.frame_id, "map");
    const double x = m.pose.position.x, y = m.pose.position.y;
    EXPECT_LT(wallDistance(x, y), cell) << "ellipse " << i << " at " << x << ", " << y;
    on_wall += wallDistance(x, y) < 0.005;
    red += m.color.r > 0.8f && m.color.b < 0.2f;
    // On an x = +-kHalfX wall, away from the corners, a cell of several end-points is long
    // along y: its major axis (scale.x) points along y.
    if (std::abs(room::kHalfX - std::abs(x)) < 0.005 && std::abs(y) < room::kHalfY - 2 * cell &&
        m.scale.x > 0.5 * cell) {
      ++long_along_x_wall;
      const double yaw = 2.0 * std::atan2(m.pose.orientation.z, m.pose.orientation.w);
      across_x_wall += std::abs(std::cos(yaw)) > 0.1;
      EXPECT_LT(m.scale.y, 0.25 * m.scale.x);  // flat across the wall
    }
  }
  const std::size_t n = msg.markers.size() - 1;
  EXPECT_GE(on_wall, n * 7 / 10) << "of " << n;
  if (scale == 0) {
    EXPECT_GE(red, n * 9 / 10) << "of " << n << ": end-point cells are occupied";
  }
  EXPECT_GT(long_along_x_wall, 0u);
  EXPECT_EQ(across_x_wall, 0u);
}

/// The cloud has the 8 float32 fields and one point per ellipse at its centre.
void checkCloud(const sensor_msgs::PointCloud2& cloud, const visualization_msgs::MarkerArray& m) {
  EXPECT_EQ(cloud.header.frame_id, "map");
  EXPECT_EQ(cloud.height, 1u);
  ASSERT_EQ(cloud.fields.size(), kFields.size());
  for (std::size_t f = 0; f < kFields.size(); ++f) {
    EXPECT_EQ(cloud.fields[f].name, kFields[f]);
    EXPECT_EQ(cloud.fields[f].datatype, sensor_msgs::PointField::FLOAT32);
  }
  const std::vector<CloudPoint> points = pointsOf(cloud);
  ASSERT_EQ(points.size() + 1, m.markers.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(points[i].x, m.markers[i + 1].pose.position.x, 1e-5);
    EXPECT_NEAR(points[i].y, m.markers[i + 1].pose.position.y, 1e-5);
    EXPECT_GT(points[i].w, 0.0f);
  }
  // The colour is the occupancy: red = P(occ), blue = 1 - P(occ).
  sensor_msgs::PointCloud2ConstIterator<float> occ(cloud, "occupancy");
  for (std::size_t i = 1; occ != occ.end(); ++occ, ++i) {
    EXPECT_GE(*occ, 0.0f);
    EXPECT_LE(*occ, 1.0f);
    EXPECT_NEAR(m.markers[i].color.r, *occ, 1e-6);
    EXPECT_NEAR(m.markers[i].color.b, 1.0f - *occ, 1e-6);
  }
}

TEST(NdtTopics, EllipsesOnTheWallsCloudAgreesScaleMergesExactly) {
  ros::NodeHandle nh;
  std::vector<ros::Publisher> pubs;
  for (int i = 1; i <= 4; ++i) {
    pubs.push_back(nh.advertise<sensor_msgs::LaserScan>("scan_" + std::to_string(i), 100));
  }
  for (const auto& p : pubs) room::waitForSubscribers(p, 2, 20.0);  // the two ndt: true nodes
  const ros::Time t0 = ros::Time::now();
  for (int k = 0; k < kScansPerLaser; ++k) {
    for (std::size_t i = 0; i < pubs.size(); ++i) {
      pubs[i].publish(room::scanOf(room::sensors()[i], t0 + ros::Duration(0.1 * k)));
    }
    ros::WallDuration(0.005).sleep();
  }
  const auto all_integrated = [](const wavog_mapping::MapperStatus& s) {
    if (s.inputs.size() != 4) return false;
    for (const auto& in : s.inputs) {
      if (in.integrated < static_cast<unsigned>(kScansPerLaser)) return false;
    }
    return true;
  };
  const auto status = room::waitLatest(&g_mutex, &g_status, all_integrated, 30.0);
  const auto half_life_status =
      room::waitLatest(&g_mutex, &g_half_life_status, all_integrated, 30.0);
  ASSERT_TRUE(status && half_life_status);
  for (const auto* st : {&status, &half_life_status}) {
    ASSERT_EQ((*st)->inputs.size(), 4u);
    for (const auto& in : (*st)->inputs) {
      ASSERT_EQ(in.integrated, static_cast<decltype(in.integrated)>(kScansPerLaser));
    }
  }
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_markers.reset();
    g_markers_2.reset();
    g_cells.reset();
    g_cells_2.reset();
    g_half_life_cells.reset();
  }
  const auto markers = fresh(&g_markers), markers_2 = fresh(&g_markers_2);
  const auto cells = fresh(&g_cells), cells_2 = fresh(&g_cells_2);
  const auto half_life_cells = fresh(&g_half_life_cells);
  ASSERT_TRUE(markers && markers_2 && cells && cells_2 && half_life_cells);

  {
    SCOPED_TRACE("ndt_markers");
    checkMarkers(*markers, 0, kResolution);
  }
  {
    SCOPED_TRACE("ndt_markers_scale_2");
    checkMarkers(*markers_2, 2, 4 * kResolution);
  }
  {
    SCOPED_TRACE("ndt_cells");
    checkCloud(*cells, *markers);
  }
  {
    SCOPED_TRACE("ndt_cells_scale_2");
    checkCloud(*cells_2, *markers_2);
  }
  // A 4 x 4 block merges its cells: fewer Gaussians, the same end-points (weight and centroid).
  const std::vector<CloudPoint> fine = pointsOf(*cells), coarse = pointsOf(*cells_2);
  EXPECT_LT(coarse.size(), fine.size());
  const auto moments = [](const std::vector<CloudPoint>& pts, double* w, double* x, double* y) {
    *w = *x = *y = 0.0;
    for (const CloudPoint& p : pts) {
      *w += p.w;
      *x += static_cast<double>(p.w) * p.x;
      *y += static_cast<double>(p.w) * p.y;
    }
  };
  double wf, xf, yf, wc, xc, yc;
  moments(fine, &wf, &xf, &yf);
  moments(coarse, &wc, &xc, &yc);
  EXPECT_GT(wf, 0.0);
  EXPECT_NEAR(wc, wf, 1e-4 * wf);
  EXPECT_NEAR(xc / wc, xf / wf, 1e-3);
  EXPECT_NEAR(yc / wc, yf / wf, 1e-3);
  // forget_half_life 60 s: each end-point weighs about 0.001 (its scan's rate), yet every cell
  // the gamma node holds a Gaussian in holds one too (it forgets less), all on the walls.
  const std::vector<CloudPoint> slow = pointsOf(*half_life_cells);
  EXPECT_GT(slow.size(), 0u) << "forget_half_life 60 s kept no Gaussian";
  EXPECT_GE(slow.size(), fine.size());
  for (const CloudPoint& p : slow) {
    EXPECT_LT(wallDistance(p.x, p.y), kResolution) << p.x << ", " << p.y;
    EXPECT_GT(p.w, 0.0f);
  }
}

TEST(NdtTopics, AdvertisedOnlyWithNdt) {
  std::vector<std::string> names;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
  bool plain_up = false;
  while (ros::WallTime::now() < end && !plain_up) {
    ros::master::V_TopicInfo topics;
    ros::master::getTopics(topics);
    names.clear();
    for (const auto& t : topics) names.push_back(t.name);
    plain_up = std::find(names.begin(), names.end(), "/plain/map") != names.end();
    if (!plain_up) ros::WallDuration(0.1).sleep();
  }
  ASSERT_TRUE(plain_up) << "the ndt: false node did not come up";
  const auto has = [&names](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  for (const std::string base : {"ndt_markers", "ndt_cells"}) {
    EXPECT_TRUE(has("/" + base)) << base;
    EXPECT_FALSE(has("/plain/" + base)) << base;
    for (int s : {2, 3, 4}) {
      const std::string scale = base + "_scale_" + std::to_string(s);
      EXPECT_TRUE(has("/" + scale)) << scale;
      EXPECT_FALSE(has("/plain/" + scale)) << scale;
    }
  }
  EXPECT_TRUE(has("/plain/map_scale_2"));
}

TEST(NdtTopics, BadMinWeightFailsAtStartUpNamingIt) {
  std::string output;
  const int code =
      room::run(std::string("timeout 8 ") + WAVOG_NODE_BIN +
                    " __name:=badndt map:=/badndt/map _ndt:=true _ndt_min_weight:=-1.0",
                &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("ndt_min_weight (-1) must be in [0, 1e6]"), std::string::npos) << output;
}

// Issue 38: a valid floor that keeps no Gaussian of a wall is named with its value at start-up
// (the missing map_file then stops the node at once).
TEST(NdtTopics, FloorOverOneEndPointIsWarnedAtStartUp) {
  std::string output;
  const int code = room::run(std::string("timeout 8 ") + WAVOG_NODE_BIN +
                                 " __name:=floorndt map:=/floorndt/map _ndt:=true"
                                 " _ndt_min_weight:=2.0 _map_file:=/nonexistent/none.wavog",
                             &output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("ndt_min_weight (2) is over 1 end-point"), std::string::npos) << output;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ndt_topics");
  ros::NodeHandle nh;
  tf2_ros::StaticTransformBroadcaster static_tf;
  static_tf.sendTransform(room::staticTree());
  auto status_sub = room::keepLatest<wavog_mapping::MapperStatus>(nh, "wavog_mapping/status", 10,
                                                                  &g_mutex, &g_status);
  auto markers_sub =
      room::keepLatest<visualization_msgs::MarkerArray>(nh, "ndt_markers", 2, &g_mutex, &g_markers);
  auto markers2_sub = room::keepLatest<visualization_msgs::MarkerArray>(nh, "ndt_markers_scale_2",
                                                                        2, &g_mutex, &g_markers_2);
  auto cells_sub =
      room::keepLatest<sensor_msgs::PointCloud2>(nh, "ndt_cells", 2, &g_mutex, &g_cells);
  auto cells2_sub =
      room::keepLatest<sensor_msgs::PointCloud2>(nh, "ndt_cells_scale_2", 2, &g_mutex, &g_cells_2);
  auto half_life_status_sub = room::keepLatest<wavog_mapping::MapperStatus>(
      nh, "half_life/wavog_mapping/status", 10, &g_mutex, &g_half_life_status);
  auto half_life_cells_sub = room::keepLatest<sensor_msgs::PointCloud2>(
      nh, "half_life/ndt_cells", 2, &g_mutex, &g_half_life_cells);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  ros::shutdown();
  return result;
}
