// PoseCheck (include/wavog_mapping/ros/pose_check.h): absurd laser poses from tf (the oko bag's
// odometry jumps to 1e22-1e32 m and -2.8e7 m for one sample and back) are refused, against the
// last accepted scan and over a sweep; mapping goes on at the next sane pose; a real jump is
// accepted once a second scan confirms it. No master needed.
#include <gtest/gtest.h>

#include <limits>

#include "wavog_mapping/ros/pose_check.h"

namespace {

using wavog::Pose2;
using wavog_ros::PoseCheck;

Pose2 at(double x, double y) { return Pose2{x, y, 0.3}; }

/// A scan without motion compensation (first and last beam at the same pose and time).
std::string still(PoseCheck* c, const Pose2& p, double t, const std::string& frame = "laser") {
  return c->check(frame, p, t, p, t);
}

TEST(PoseCheck, OkoLikeOdometryJumpsRefusedAndMappingGoesOn) {
  PoseCheck c;
  EXPECT_EQ(still(&c, at(0.15, -0.14), 0.0), "");
  EXPECT_EQ(still(&c, at(0.16, -0.14), 0.8), "");
  // tf interpolated towards a sample at y = 1.9e32, at -2.76e7 (inside the 5 cm extent), and
  // at 5.9e22: each refused, naming the speed.
  for (const double y : {1.9e32, -2.76e7, -2.76e5, 5.9e22}) {
    const std::string why = still(&c, at(0.16, y), 1.6);
    EXPECT_NE(why.find("faster than max_sensor_speed 50 m/s"), std::string::npos)
        << y << ": " << why;
  }
  // The next sane pose (0.8 s later, a few cm on) is taken: the reference is the last accepted.
  EXPECT_EQ(still(&c, at(0.17, -0.13), 2.4), "");
  // Two refusals in a row that disagree with each other do not confirm one another.
  EXPECT_NE(still(&c, at(5e22, 0.0), 3.2), "");
  EXPECT_NE(still(&c, at(0.0, 1.5e25), 4.0), "");
  EXPECT_EQ(still(&c, at(0.18, -0.13), 4.8), "");
}

TEST(PoseCheck, JumpOverTheSweepRefused) {
  PoseCheck c;
  // First beam sane, last beam 0.98 s later at an absurd sample: refused even without history.
  const std::string why = c.check("laser", at(0.65, 0.17), 0.0, at(0.65, -2.76e7), 0.98);
  EXPECT_NE(why.find("over its sweep"), std::string::npos) << why;
  // A real sweep (0.5 m in 0.98 s) is fine.
  EXPECT_EQ(c.check("laser", at(0.65, 0.17), 2.0, at(1.15, 0.17), 2.98), "");
}

TEST(PoseCheck, NonFinitePoseRefused) {
  PoseCheck c;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(still(&c, at(nan, 0.0), 0.0), "");
  EXPECT_NE(still(&c, at(0.0, inf), 0.0), "");
  EXPECT_NE(still(&c, Pose2{0.0, 0.0, nan}, 0.0), "");
  EXPECT_EQ(still(&c, at(0.0, 0.0), 1.0), "");
}

TEST(PoseCheck, RealJumpConfirmedByTheNextScan) {
  PoseCheck c;
  EXPECT_EQ(still(&c, at(0.0, 0.0), 0.0), "");
  // A relocalisation moves the laser 200 m at once: the first scan there is refused, the second,
  // which agrees with it, is accepted, and mapping goes on from there.
  EXPECT_NE(still(&c, at(200.0, 0.0), 0.1), "");
  EXPECT_EQ(still(&c, at(200.1, 0.0), 0.2), "");
  EXPECT_EQ(still(&c, at(200.2, 0.0), 0.3), "");
}

TEST(PoseCheck, MaxSensorSpeedSetsTheBound) {
  // A car at 60 m/s (216 km/h) is refused by the default 50 m/s and accepted at 80 m/s; at 1 m/s
  // (a slow indoor robot) a 3 m jump in 1 s is refused.
  PoseCheck slow_default, fast(80.0), indoor(1.0);
  for (PoseCheck* c : {&slow_default, &fast, &indoor}) EXPECT_EQ(still(c, at(0.0, 0.0), 0.0), "");
  EXPECT_NE(still(&slow_default, at(60.0, 0.0), 1.0), "");
  EXPECT_EQ(still(&fast, at(60.0, 0.0), 1.0), "");
  const std::string why = still(&indoor, at(3.0, 0.0), 1.0);
  EXPECT_NE(why.find("faster than max_sensor_speed 1 m/s"), std::string::npos) << why;
  EXPECT_EQ(still(&indoor, at(1.5, 0.0), 1.0), "");  // 1 m/s x 1 s + 1 m of slack
}

TEST(PoseCheck, FramesAndTimeScaleTheBound) {
  PoseCheck c;
  EXPECT_EQ(still(&c, at(0.0, 0.0), 0.0, "a"), "");
  // Another laser 2e5 m away (another frame of the same input) has its own history.
  EXPECT_EQ(still(&c, at(2e5, 0.0), 0.1, "b"), "");
  EXPECT_EQ(still(&c, at(0.1, 0.0), 0.2, "a"), "");
  // 400 m after 10 s (40 m/s) is plausible; 400 m more after 1 s is not.
  EXPECT_EQ(still(&c, at(400.0, 0.0), 10.2, "a"), "");
  EXPECT_NE(still(&c, at(800.0, 0.0), 11.2, "a"), "");
  // Stamps going back (a bag restarted) count by their distance in time as well.
  EXPECT_EQ(still(&c, at(0.0, 0.0), 0.5, "a"), "");
}

}  // namespace
