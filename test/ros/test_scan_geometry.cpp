// Other people's scan geometry (issue 27): beam i at angle_min + i * angle_increment for every
// range, as laser_geometry, costmap_2d and Cartographer place them; angle_max is not used. A range
// count that disagrees with the angles, or intensities of another length, is integrated (counted
// by the node); a full turn whose increment is rounded up is spread over 2 pi; the core's geometry
// refusals are named by limit and value. Values from the three bags of ../shared/data/bags. No
// master needed.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/conversions.h"

namespace {

using wavog_ros::DropReason;

sensor_msgs::LaserScan scanOf(std::size_t beams, float angle_min, float angle_max, float inc) {
  sensor_msgs::LaserScan s;
  s.header.frame_id = "laser";
  s.angle_min = angle_min;
  s.angle_max = angle_max;
  s.angle_increment = inc;
  s.range_min = 0.1f;
  s.range_max = 3.0f;
  s.ranges.assign(beams, 1.0f);
  return s;
}

/// oko: 64 beams whose angles imply 49, 64 x increment = 2 pi + 1.4e-5.
sensor_msgs::LaserScan oko() { return scanOf(64, -1.3046f, 3.4078f, 0.098175f); }

TEST(ScanGeometry, CountDisagreeingWithTheAnglesIsNotDropped) {
  const sensor_msgs::LaserScan s = oko();
  DropReason reason = DropReason::kException;
  EXPECT_TRUE(wavog_ros::checkScan(s, &reason));
  EXPECT_TRUE(wavog_ros::beamCountMismatch(s));
  EXPECT_NEAR(wavog_ros::impliedBeams(s), 49.0, 1e-3);
  // johnny5 (angle_max one increment too far: 361 implied for 360) and datmo are within the
  // one beam of slack drivers need.
  EXPECT_FALSE(wavog_ros::beamCountMismatch(scanOf(360, 0.0f, 6.2831855f, 0.017453292f)));
  EXPECT_FALSE(wavog_ros::beamCountMismatch(scanOf(360, -3.124139f, 3.1415927f, 0.017453292f)));
  // angle_max is not used for geometry: not finite, the scan still goes on (a mismatch).
  sensor_msgs::LaserScan no_max = oko();
  no_max.angle_max = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(wavog_ros::checkScan(no_max, &reason));
  EXPECT_TRUE(wavog_ros::beamCountMismatch(no_max));
  // What cannot be placed still is dropped.
  sensor_msgs::LaserScan no_inc = oko();
  no_inc.angle_increment = 0.0f;
  EXPECT_FALSE(wavog_ros::checkScan(no_inc, &reason));
  EXPECT_EQ(reason, DropReason::kBadAngles);
}

TEST(ScanGeometry, IntensitiesOfAnotherLengthAreAMismatchNotADrop) {
  sensor_msgs::LaserScan s = oko();
  EXPECT_FALSE(wavog_ros::intensitiesMismatch(s));  // none: fine
  s.intensities.assign(64, 1.0f);
  EXPECT_FALSE(wavog_ros::intensitiesMismatch(s));
  s.intensities.resize(3);
  EXPECT_TRUE(wavog_ros::intensitiesMismatch(s));
  DropReason reason{};
  EXPECT_TRUE(wavog_ros::checkScan(s, &reason));
}

TEST(ScanGeometry, RoundedFullTurnIsMappedBeamsAtAngleMinPlusIIncrement) {
  const sensor_msgs::LaserScan s = oko();
  const wavog::ScanView v = wavog_ros::toScanView(s);
  EXPECT_EQ(v.count, 64u);
  EXPECT_DOUBLE_EQ(v.angle_min, static_cast<double>(s.angle_min));
  EXPECT_NEAR(v.angle_increment * 64.0, 2.0 * M_PI, 1e-12);
  // The core takes it (it refuses a field of view beyond 2 pi + 1e-6 rad).
  wavog::WaveletMap map{wavog::MapParams{}};
  const wavog::IntegrateStats st = map.integrate(wavog::Pose2{}, v);
  EXPECT_EQ(st.status, wavog::ScanStatus::kOk);
  EXPECT_EQ(st.beams_hit, 64u);
  // A field of view truly beyond a turn is left for the core to refuse, and named.
  sensor_msgs::LaserScan wide = scanOf(64, 0.0f, 6.5f, 0.103f);
  const wavog::ScanView w = wavog_ros::toScanView(wide);
  EXPECT_FLOAT_EQ(static_cast<float>(w.angle_increment), 0.103f);
  EXPECT_EQ(map.integrate(wavog::Pose2{}, w).status, wavog::ScanStatus::kBadGeometry);
  const std::string why = wavog_ros::geometryRefusal(w);
  EXPECT_NE(why.find("field of view"), std::string::npos) << why;
  EXPECT_NE(why.find("2 pi"), std::string::npos) << why;
}

TEST(ScanGeometry, GeometryRefusalNamesTheLimitAndTheValue) {
  sensor_msgs::LaserScan s = oko();
  s.range_min = 50.0f;
  s.range_max = 10.0f;
  const std::string range = wavog_ros::geometryRefusal(wavog_ros::toScanView(s));
  EXPECT_NE(range.find("range_max 10"), std::string::npos) << range;
  EXPECT_NE(range.find("range_min 50"), std::string::npos) << range;
  s = oko();
  s.angle_min = 1000.0f;
  const std::string amin = wavog_ros::geometryRefusal(wavog_ros::toScanView(s));
  EXPECT_NE(amin.find("angle_min"), std::string::npos) << amin;
  EXPECT_NE(amin.find("1000"), std::string::npos) << amin;
  s = oko();
  s.range_min = -1.0f;
  const std::string neg = wavog_ros::geometryRefusal(wavog_ros::toScanView(s));
  EXPECT_NE(neg.find("range_min -1"), std::string::npos) << neg;
}

TEST(ScanGeometry, NoValidBeamBeyondTheHardLimitIsNotCalledNaN) {
  // Issue 28: 1e6 beams at 3 m, whose work budget makes the hard range limit 0.42 m at 5 cm, were
  // logged as "every beam is NaN, -inf or below range_min".
  sensor_msgs::LaserScan many = scanOf(1000000, -3.1f, 3.1f, 6.2f / 1e6f);
  many.range_max = 80.0f;
  many.ranges.assign(1000000, 3.0f);
  const wavog::MapParams params;
  wavog::WaveletMap map{params};
  const wavog::ScanView v = wavog_ros::toScanView(many);
  const wavog::IntegrateStats st = map.integrate(wavog::Pose2{}, v);
  ASSERT_EQ(st.status, wavog::ScanStatus::kNoValidBeam);
  EXPECT_EQ(st.beams_beyond_limit, 1000000u);
  const std::string why = wavog_ros::coreRefusal(st, v, wavog::Pose2{}, params);
  EXPECT_EQ(why.find("every beam is NaN"), std::string::npos) << why;
  EXPECT_NE(why.find("1000000 beyond the hard range limit of 0.4"), std::string::npos) << why;
  // Out of extent names the pose and the extent; bad geometry the limit.
  wavog::IntegrateStats far;
  far.status = wavog::ScanStatus::kOutOfExtent;
  const std::string extent = wavog_ros::coreRefusal(far, v, wavog::Pose2{5e10, 0.0, 0.0}, params);
  EXPECT_NE(extent.find("out_of_extent"), std::string::npos) << extent;
  EXPECT_NE(extent.find("5e+10"), std::string::npos) << extent;
  wavog::IntegrateStats bad;
  bad.status = wavog::ScanStatus::kBadGeometry;
  sensor_msgs::LaserScan limits = oko();
  limits.range_min = 50.0f;
  limits.range_max = 10.0f;
  const std::string geometry =
      wavog_ros::coreRefusal(bad, wavog_ros::toScanView(limits), wavog::Pose2{}, params);
  EXPECT_NE(geometry.find("bad_geometry"), std::string::npos) << geometry;
  EXPECT_NE(geometry.find("range_max 10 m is not above range_min 50 m"), std::string::npos)
      << geometry;
}

}  // namespace
