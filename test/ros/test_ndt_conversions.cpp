// The NDT conversions without a roscore: NdtLayer -> visualization_msgs/MarkerArray (a DELETEALL,
// then one flat 2-sigma ellipse per Gaussian, coloured by occupancy) and -> sensor_msgs/PointCloud2
// (fields x, y, z, cov_xx, cov_xy, cov_yy, weight, occupancy), read back through sensor_msgs'
// iterators.
#include <gtest/gtest.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <string>
#include <vector>

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/conversions.h"

namespace {

using wavog_ros::ndtEllipse;
using wavog_ros::toNdtCloud;
using wavog_ros::toNdtMarkers;

constexpr double kPi = 3.14159265358979323846;

/// R(theta) diag(a, b) R(theta)^T.
wavog::NdtCell rotatedCell(double a, double b, double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  wavog::NdtCell cell;
  cell.cov_xx = a * c * c + b * s * s;
  cell.cov_yy = a * s * s + b * c * c;
  cell.cov_xy = (a - b) * c * s;
  return cell;
}

double yawOf(const visualization_msgs::Marker& m) {
  EXPECT_DOUBLE_EQ(m.pose.orientation.x, 0.0);
  EXPECT_DOUBLE_EQ(m.pose.orientation.y, 0.0);
  return 2.0 * std::atan2(m.pose.orientation.z, m.pose.orientation.w);
}

/// A scale-1 layer (0.1 m cells) of three Gaussians: an occupied wall segment along a 30 deg
/// line, a free cell, and a cell of one end-point (covariance 0).
wavog::NdtLayer sampleLayer() {
  wavog::NdtLayer layer;
  layer.scale = 1;
  layer.cell_size = 0.1;
  wavog::NdtCell wall = rotatedCell(0.04, 0.01, kPi / 6);
  wall.ix = 10;
  wall.iy = 3;
  wall.mean_x = 1.04;
  wall.mean_y = 0.33;
  wall.weight = 12.5;
  wall.log_odds = 3.5f;
  wavog::NdtCell free_cell;
  free_cell.ix = -2;
  free_cell.iy = 4;
  free_cell.mean_x = -0.17;
  free_cell.mean_y = 0.41;
  free_cell.cov_xx = 0.0004;
  free_cell.cov_yy = 0.0009;
  free_cell.weight = 0.5;
  free_cell.log_odds = -2.0f;
  wavog::NdtCell single;
  single.ix = 7;
  single.iy = 5;
  single.mean_x = 0.71;
  single.mean_y = 0.52;
  single.weight = 1.0;
  single.log_odds = 0.0f;
  layer.cells = {free_cell, wall, single};
  return layer;
}

TEST(NdtEllipse, AxesAreTwoSigmaDiameters) {
  double major = 0, minor = 0, yaw = 1;
  ndtEllipse(0.04, 0.0, 0.01, &major, &minor, &yaw);
  EXPECT_NEAR(major, 0.8, 1e-12);  // 2 x 2 sigma, sigma = 0.2 m
  EXPECT_NEAR(minor, 0.4, 1e-12);
  EXPECT_NEAR(yaw, 0.0, 1e-12);
  // The major axis along y.
  ndtEllipse(0.01, 0.0, 0.04, &major, &minor, &yaw);
  EXPECT_NEAR(major, 0.8, 1e-12);
  EXPECT_NEAR(minor, 0.4, 1e-12);
  EXPECT_NEAR(std::abs(yaw), kPi / 2, 1e-12);
  // One point: nothing; a line: no width.
  ndtEllipse(0.0, 0.0, 0.0, &major, &minor, &yaw);
  EXPECT_EQ(major, 0.0);
  EXPECT_EQ(minor, 0.0);
  ndtEllipse(0.01, 0.01, 0.01, &major, &minor, &yaw);  // all along x = y
  EXPECT_NEAR(major, 4.0 * std::sqrt(0.02), 1e-12);
  EXPECT_NEAR(minor, 0.0, 1e-6);
  EXPECT_NEAR(yaw, kPi / 4, 1e-12);
}

TEST(NdtEllipse, RotatedCovarianceGivesItsYaw) {
  for (const double theta : {0.3, kPi / 6, 1.2, 2.0, -0.7, 3.0}) {
    SCOPED_TRACE(theta);
    const wavog::NdtCell c = rotatedCell(0.04, 0.01, theta);
    double major = 0, minor = 0, yaw = 0;
    ndtEllipse(c.cov_xx, c.cov_xy, c.cov_yy, &major, &minor, &yaw);
    EXPECT_NEAR(major, 0.8, 1e-9);
    EXPECT_NEAR(minor, 0.4, 1e-9);
    // The same axis as theta (an axis has no sign: modulo pi).
    const double d = std::remainder(yaw - theta, kPi);
    EXPECT_NEAR(d, 0.0, 1e-9);
    // (cos yaw, sin yaw) is the eigenvector of the larger eigenvalue.
    const double vx = std::cos(yaw), vy = std::sin(yaw);
    EXPECT_NEAR(c.cov_xx * vx + c.cov_xy * vy, 0.04 * vx, 1e-12);
    EXPECT_NEAR(c.cov_xy * vx + c.cov_yy * vy, 0.04 * vy, 1e-12);
  }
}

TEST(NdtMarkers, DeleteAllThenOneEllipsePerGaussian) {
  const wavog::NdtLayer layer = sampleLayer();
  const ros::Time stamp(12.5);
  const auto msg = toNdtMarkers(layer, "map", stamp);
  ASSERT_EQ(msg->markers.size(), layer.cells.size() + 1);
  const visualization_msgs::Marker& clear = msg->markers[0];
  EXPECT_EQ(clear.action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(clear.ns, "ndt_scale_1");
  EXPECT_EQ(clear.header.frame_id, "map");
  for (std::size_t i = 0; i < layer.cells.size(); ++i) {
    SCOPED_TRACE(i);
    const visualization_msgs::Marker& m = msg->markers[i + 1];
    const wavog::NdtCell& c = layer.cells[i];
    EXPECT_EQ(m.action, visualization_msgs::Marker::ADD);
    EXPECT_EQ(m.type, visualization_msgs::Marker::CYLINDER);
    EXPECT_EQ(m.ns, "ndt_scale_1");
    EXPECT_EQ(m.id, static_cast<int>(i + 1));
    EXPECT_EQ(m.header.frame_id, "map");
    EXPECT_EQ(m.header.stamp, stamp);
    EXPECT_DOUBLE_EQ(m.pose.position.x, c.mean_x);
    EXPECT_DOUBLE_EQ(m.pose.position.y, c.mean_y);
    EXPECT_GT(m.scale.z, 0.0);
    EXPECT_LT(m.scale.z, 0.05);  // flat
    EXPECT_NEAR(m.pose.orientation.x * m.pose.orientation.x +
                    m.pose.orientation.y * m.pose.orientation.y +
                    m.pose.orientation.z * m.pose.orientation.z +
                    m.pose.orientation.w * m.pose.orientation.w,
                1.0, 1e-12);
    EXPECT_GT(m.color.a, 0.0f);
  }
  // The wall: 0.8 x 0.4 m along 30 deg, red.
  const visualization_msgs::Marker& wall = msg->markers[2];
  EXPECT_NEAR(wall.scale.x, 0.8, 1e-9);
  EXPECT_NEAR(wall.scale.y, 0.4, 1e-9);
  EXPECT_NEAR(std::remainder(yawOf(wall) - kPi / 6, kPi), 0.0, 1e-9);
  EXPECT_GT(wall.color.r, 0.9f);
  EXPECT_LT(wall.color.b, 0.1f);
  // The free cell: sigma 0.03 m along y, 0.02 m along x (major axis along y), blue.
  const visualization_msgs::Marker& free_m = msg->markers[1];
  EXPECT_NEAR(free_m.scale.x, 0.12, 1e-9);
  EXPECT_NEAR(free_m.scale.y, 0.08, 1e-9);
  EXPECT_NEAR(std::abs(std::remainder(yawOf(free_m), kPi)), kPi / 2, 1e-9);
  EXPECT_GT(free_m.color.b, 0.8f);
  EXPECT_LT(free_m.color.r, 0.2f);
  EXPECT_GT(free_m.color.b, wall.color.b);
  EXPECT_LT(free_m.color.r, wall.color.r);
  // One end-point: drawn at the floor, 0.1 x the cell size; P(occ) 0.5 halfway.
  const visualization_msgs::Marker& single = msg->markers[3];
  EXPECT_NEAR(single.scale.x, 0.01, 1e-12);
  EXPECT_NEAR(single.scale.y, 0.01, 1e-12);
  EXPECT_NEAR(single.color.r, 0.5f, 1e-6);
  EXPECT_NEAR(single.color.b, 0.5f, 1e-6);
}

TEST(NdtMarkers, EmptyLayerOnlyClears) {
  wavog::NdtLayer layer;
  layer.scale = 0;
  layer.cell_size = 0.05;
  const auto msg = toNdtMarkers(layer, "odom", ros::Time(1.0));
  ASSERT_EQ(msg->markers.size(), 1u);
  EXPECT_EQ(msg->markers[0].action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(msg->markers[0].ns, "ndt_scale_0");
  EXPECT_EQ(msg->markers[0].header.frame_id, "odom");
}

TEST(NdtCloud, FloatFieldsReadBackByIterators) {
  const wavog::NdtLayer layer = sampleLayer();
  const auto msg = toNdtCloud(layer, "map", ros::Time(3.0));
  EXPECT_EQ(msg->header.frame_id, "map");
  EXPECT_EQ(msg->header.stamp, ros::Time(3.0));
  EXPECT_EQ(msg->height, 1u);
  EXPECT_EQ(msg->width, layer.cells.size());
  const std::vector<std::string> names = {"x",      "y",      "z",      "cov_xx",
                                          "cov_xy", "cov_yy", "weight", "occupancy"};
  ASSERT_EQ(msg->fields.size(), names.size());
  for (std::size_t f = 0; f < names.size(); ++f) {
    EXPECT_EQ(msg->fields[f].name, names[f]);
    EXPECT_EQ(msg->fields[f].datatype, sensor_msgs::PointField::FLOAT32);
    EXPECT_EQ(msg->fields[f].count, 1u);
    EXPECT_EQ(msg->fields[f].offset, 4 * f);
  }
  EXPECT_EQ(msg->point_step, 32u);
  EXPECT_EQ(msg->row_step, 32u * layer.cells.size());
  EXPECT_EQ(msg->data.size(), msg->row_step);
  EXPECT_FALSE(msg->is_bigendian);

  sensor_msgs::PointCloud2ConstIterator<float> x(*msg, "x"), y(*msg, "y"), z(*msg, "z"),
      xx(*msg, "cov_xx"), xy(*msg, "cov_xy"), yy(*msg, "cov_yy"), w(*msg, "weight"),
      occ(*msg, "occupancy");
  for (const wavog::NdtCell& c : layer.cells) {
    EXPECT_FLOAT_EQ(*x, static_cast<float>(c.mean_x));
    EXPECT_FLOAT_EQ(*y, static_cast<float>(c.mean_y));
    EXPECT_EQ(*z, 0.0f);
    EXPECT_FLOAT_EQ(*xx, static_cast<float>(c.cov_xx));
    EXPECT_FLOAT_EQ(*xy, static_cast<float>(c.cov_xy));
    EXPECT_FLOAT_EQ(*yy, static_cast<float>(c.cov_yy));
    EXPECT_FLOAT_EQ(*w, static_cast<float>(c.weight));
    EXPECT_NEAR(*occ, 1.0 / (1.0 + std::exp(-static_cast<double>(c.log_odds))), 1e-6);
    ++x, ++y, ++z, ++xx, ++xy, ++yy, ++w, ++occ;
  }
  EXPECT_FALSE(x != x.end());
  // The wall is occupied, the free cell free, the single point halfway.
  // (operator[] of these iterators indexes fields within a point; + steps over points.)
  sensor_msgs::PointCloud2ConstIterator<float> o(*msg, "occupancy");
  EXPECT_LT(*o, 0.2f);
  EXPECT_GT(*(o + 1), 0.95f);
  EXPECT_FLOAT_EQ(*(o + 2), 0.5f);
}

TEST(NdtCloud, EmptyLayerKeepsItsFields) {
  wavog::NdtLayer layer;
  layer.cell_size = 0.05;
  const auto msg = toNdtCloud(layer, "map", ros::Time(1.0));
  EXPECT_EQ(msg->width, 0u);
  EXPECT_EQ(msg->height, 1u);
  EXPECT_EQ(msg->fields.size(), 8u);
  EXPECT_TRUE(msg->data.empty());
}

}  // namespace
