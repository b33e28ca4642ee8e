// Scan placement (scan_placement.h), no master: a tf2::BufferCore filled in the test. A robot
// drives along x at 1 m/s with a laser mounted upside down 0.2 m ahead of base_link: the placement
// finds the poses at the first and last beam, mirrors the view and re-bins the sweep, and the map
// holds the short beam's hit where the mirrored laser saw it. Then every way a placement can fail
// or fall back, and the fixed-frame shortcut.
#include <gtest/gtest.h>
#include <tf2/buffer_core.h>

#include <cmath>
#include <vector>

#include "driving_laser.h"
#include "tf_messages.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace {

using namespace driving_laser;  // NOLINT(google-build-using-namespace): the scenario's names

/// The drive's tf in a buffer.
class DrivingTf : public tf2::BufferCore {
 public:
  DrivingTf() : tf2::BufferCore(ros::Duration(3600.0)) {
    setTransform(mount("laser_down"), "test", true);
    for (const auto& t : drive()) setTransform(t, "test", false);
  }
};

sensor_msgs::LaserScan scanAt(double t) { return driving_laser::scanAt(t, "laser_down"); }
sensor_msgs::LaserScan scanAt(double t, const std::string& frame) {
  return driving_laser::scanAt(t, frame);
}

TEST(ScanPlacement, UpsideDownLaserOnAMovingRobotIsMirroredAndCompensated) {
  const DrivingTf tf;
  const wavog_ros::PlacementOptions options;  // fixed frame "map", compensation on
  wavog::WaveletMap map(wavog::MapParams::defaultsFor(wavog::PolicyType::kForget));
  wavog::MotionCompensator compensator;
  double last_x = 0.0;
  for (int i = 0; i < kScans; ++i) {
    const double t = scanTime(i);
    const sensor_msgs::LaserScan scan = scanAt(t);
    const wavog_ros::ScanPlacement p = wavog_ros::placeScan(tf, scan, options);
    ASSERT_TRUE(p.placed()) << p.error;
    EXPECT_TRUE(p.mirrored);
    EXPECT_TRUE(p.compensate);
    EXPECT_FALSE(p.motion_fallback);
    EXPECT_NEAR(p.start.x, kMount + kSpeed * t, 1e-9);
    EXPECT_NEAR(p.end.x, kMount + kSpeed * (t + kSweep), 1e-9);
    EXPECT_NEAR(p.start.y, 0.0, 1e-12);
    EXPECT_NEAR(p.start.theta, 0.0, 1e-12);  // rolled, not turned: its x axis still points ahead
    wavog::Pose2 pose;
    const wavog::ScanView view = p.placedView(scan, &compensator, &pose);
    EXPECT_NEAR(pose.x, kMount + kSpeed * (t + kSweep / 2), 1e-9);  // the middle of the sweep
    EXPECT_DOUBLE_EQ(view.angle_min, -static_cast<double>(scan.angle_min));
    EXPECT_DOUBLE_EQ(view.angle_increment, -static_cast<double>(scan.angle_increment));
    EXPECT_NE(view.ranges, scan.ranges.data());  // re-binned into the compensator's buffer
    EXPECT_EQ(map.integrate(pose, view).status, wavog::ScanStatus::kOk);
    last_x = pose.x;
  }
  // The last scan's short beam hit the map at -45 deg from the laser (mirrored), not at +45 deg.
  // With forgetting (gamma 0.3), one hit on a cell seen free before lifts it from about -2 to
  // 0.7 * -2 + 0.3 * 3.5 = -0.35; its mirror image stays free.
  const double c = std::cos(M_PI / 4);
  EXPECT_GT(map.value(map.cellAt(last_x + c, -c)), -0.5f);
  EXPECT_LT(map.value(map.cellAt(last_x + c, c)), -1.5f);
}

TEST(ScanPlacement, ScanInTheFixedFrameIsHeldAtTheOriginWithoutTf) {
  const tf2::BufferCore empty;
  wavog_ros::PlacementOptions options;
  options.fixed_frame = "laser";
  const sensor_msgs::LaserScan scan = scanAt(0.5, "laser");
  const wavog_ros::ScanPlacement p = wavog_ros::placeScan(empty, scan, options);
  ASSERT_TRUE(p.placed()) << p.error;
  EXPECT_FALSE(p.compensate);
  EXPECT_FALSE(p.motion_fallback);
  EXPECT_FALSE(p.mirrored);
  wavog::MotionCompensator compensator;
  wavog::Pose2 pose{1.0, 2.0, 3.0};
  const wavog::ScanView view = p.placedView(scan, &compensator, &pose);
  EXPECT_EQ(pose.x, 0.0);
  EXPECT_EQ(pose.y, 0.0);
  EXPECT_EQ(pose.theta, 0.0);
  EXPECT_EQ(view.ranges, scan.ranges.data());  // the message's own beams
  EXPECT_DOUBLE_EQ(view.angle_min, static_cast<double>(scan.angle_min));
}

TEST(ScanPlacement, UnknownFrameIsUnavailable) {
  const DrivingTf tf;
  const wavog_ros::ScanPlacement p =
      wavog_ros::placeScan(tf, scanAt(0.5, "nowhere"), wavog_ros::PlacementOptions{});
  EXPECT_FALSE(p.placed());
  EXPECT_EQ(p.failure, wavog_ros::TfFailure::kUnavailable);
  EXPECT_NE(p.error.find("nowhere"), std::string::npos) << p.error;
}

TEST(ScanPlacement, StampOutsideTheTfIsExtrapolation) {
  const DrivingTf tf;
  for (const double t : {-5.0, kTfSeconds + 5.0}) {
    const wavog_ros::ScanPlacement p =
        wavog_ros::placeScan(tf, scanAt(t), wavog_ros::PlacementOptions{});
    EXPECT_FALSE(p.placed()) << t;
    EXPECT_EQ(p.failure, wavog_ros::TfFailure::kExtrapolation) << t;
    EXPECT_FALSE(p.error.empty());
  }
}

TEST(ScanPlacement, NoTfAtTheLastBeamPlacesTheScanUncompensated) {
  const DrivingTf tf;
  const double t = kTfSeconds - kSweep / 2;  // first beam inside tf, last beam after it
  const sensor_msgs::LaserScan scan = scanAt(t);
  const wavog_ros::ScanPlacement p = wavog_ros::placeScan(tf, scan, wavog_ros::PlacementOptions{});
  ASSERT_TRUE(p.placed()) << p.error;
  EXPECT_TRUE(p.motion_fallback);
  EXPECT_TRUE(p.end_missing);  // the node waits for this tf
  EXPECT_FALSE(p.compensate);
  ros::Time end;
  ASSERT_TRUE(wavog_ros::sweepEndStamp(scan, wavog_ros::PlacementOptions{}, &end));
  EXPECT_NEAR(end.toSec() - scan.header.stamp.toSec(), kSweep, 1e-6);
  wavog::MotionCompensator compensator;
  wavog::Pose2 pose;
  const wavog::ScanView view = p.placedView(scan, &compensator, &pose);
  EXPECT_NEAR(pose.x, kMount + kSpeed * t, 1e-9);  // the first beam's pose
  EXPECT_EQ(view.ranges, scan.ranges.data());
  EXPECT_DOUBLE_EQ(view.angle_min, -static_cast<double>(scan.angle_min));  // still mirrored
}

TEST(ScanPlacement, CompensationOffOrUntimedBeamsUseTheStampOnly) {
  const DrivingTf tf;
  wavog_ros::PlacementOptions off;
  off.motion_compensation = false;
  sensor_msgs::LaserScan untimed = scanAt(0.5);
  untimed.time_increment = 0.0f;
  for (const auto& [scan, options] :
       {std::make_pair(scanAt(0.5), off), std::make_pair(untimed, wavog_ros::PlacementOptions{})}) {
    const wavog_ros::ScanPlacement p = wavog_ros::placeScan(tf, scan, options);
    ASSERT_TRUE(p.placed()) << p.error;
    EXPECT_FALSE(p.compensate);
    EXPECT_FALSE(p.motion_fallback);
    EXPECT_FALSE(p.end_missing);
    ros::Time end;
    EXPECT_FALSE(wavog_ros::sweepEndStamp(scan, options, &end));  // nothing to wait for
    EXPECT_NEAR(p.start.x, kMount + kSpeed * 0.5, 1e-9);
    EXPECT_EQ(p.end.x, p.start.x);
  }
}

// Issue 41: what the node says when tf cannot place a scan names the frame tf lacks (the
// laser's, not the map frame that exists) and the frames tf has; a skipped motion compensation
// names tf_tolerance against the sweep.
TEST(TfMessages, NameTheMissingFrameAndTheFramesTfHas) {
  const DrivingTf tf;  // map <- base_link <- laser_down
  std::string text = wavog_ros::noTransformText(tf, "laser", "map", 10);
  EXPECT_NE(text.find("the scan's frame 'laser' is not in tf"), std::string::npos) << text;
  EXPECT_NE(text.find("frames tf has: base_link, laser_down, map"), std::string::npos) << text;
  EXPECT_NE(text.find("laser_parent:=<frame> laser_frame:=laser"), std::string::npos) << text;
  text = wavog_ros::noTransformText(tf, "laser_down", "odom", 10);
  EXPECT_NE(text.find("the map frame 'odom' is not in tf"), std::string::npos) << text;
  // Known frames, a scan stamp tf does not reach: neither frame is missing.
  text = wavog_ros::noTransformText(tf, "laser_down", "map", 7);
  EXPECT_NE(text.find("at the scan's stamp"), std::string::npos) << text;
  EXPECT_NE(text.find("queue_size 7"), std::string::npos) << text;
  EXPECT_EQ(text.find("not in tf"), std::string::npos) << text;
  // Two trees tf does not join.
  tf2::BufferCore apart;
  apart.setTransform(driving_laser::transform("map", "base_link", 0, 0, 0, kT0), "test", true);
  apart.setTransform(driving_laser::transform("odom", "laser", 0, 0, 0, kT0), "test", true);
  text = wavog_ros::noTransformText(apart, "laser", "map", 10);
  EXPECT_NE(text.find("tf does not connect them (frames tf has: base_link, laser, map, odom)"),
            std::string::npos)
      << text;
  EXPECT_EQ(wavog_ros::framesOf(tf2::BufferCore()), "none");
  EXPECT_EQ(wavog_ros::framesOf(apart, 2), "base_link, laser and 2 more");
}

TEST(TfMessages, ASkippedCompensationNamesTheSweepAndTheBound) {
  const std::string text = wavog_ros::motionFallbackText(10, 0.99);
  EXPECT_NE(text.find("0.99 s after the scan's stamp"), std::string::npos) << text;
  EXPECT_NE(text.find("queue_size 10"), std::string::npos) << text;
  EXPECT_NE(text.find("time_increment"), std::string::npos) << text;
  EXPECT_NE(text.find("motion_compensation: false"), std::string::npos) << text;
}

}  // namespace
