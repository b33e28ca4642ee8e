// The 16-bit range codes of the fleet stream (range_codec.h, PlacedScan version 2): a return
// decodes within half a step of its reading and stays a return, the core's invalid and no-return
// readings keep their class, the step widens for a long reach so that every return keeps a code,
// and the core classifies the decoded scan's beams as it classified the readings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "fleet/range_codec.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

using wavog_fleet::decodeRange;
using wavog_fleet::kInvalidCode;
using wavog_fleet::kMaxHitCode;
using wavog_fleet::kNoReturnCode;
using wavog_fleet::kRangeStep;
using wavog_fleet::RangeCodec;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

wavog::MapParams params10cm() {
  wavog::MapParams p;
  p.grid.resolution = 0.1;
  return p;
}

wavog::ScanView viewOf(const std::vector<float>& r, double range_min, double range_max) {
  wavog::ScanView v;
  v.ranges = r.data();
  v.count = r.size();
  v.angle_min = -M_PI / 2;
  v.angle_increment = M_PI / static_cast<double>(r.size());
  v.range_min = range_min;
  v.range_max = range_max;
  return v;
}

enum class Kind { kInvalid, kNoReturn, kReturn };
/// The core's class of a reading (classify/prepared_scan.cpp).
Kind kindOf(double z, double range_min, double reach) {
  if (std::isnan(z) || z <= 0.0 || z < range_min) return Kind::kInvalid;
  return z >= reach ? Kind::kNoReturn : Kind::kReturn;
}

TEST(RangeCodec, ReturnsRoundTripWithinHalfAStep) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> z(0.06f, 79.99f);
  std::vector<float> r(4000);
  for (float& x : r) x = z(rng);
  const wavog::ScanView view = viewOf(r, 0.06, 80.0);
  RangeCodec c;
  ASSERT_TRUE(c.encode(view, params10cm()));
  // 80 m reach: above 65.534 m, so the step widens to reach / 65534 (1.22 mm).
  const double reach = wavog_fleet::scanReach(params10cm(), 80.0, r.size(), view.angle_increment);
  EXPECT_EQ(reach, 80.0);
  EXPECT_DOUBLE_EQ(c.step(), 80.0 / kMaxHitCode);
  ASSERT_EQ(c.codes().size(), r.size());
  for (std::size_t j = 0; j < r.size(); ++j) {
    const std::uint16_t k = c.codes()[j];
    ASSERT_GE(k, 1);
    ASSERT_LE(k, kMaxHitCode);
    const float d = c.decoded()[j];
    EXPECT_EQ(d, decodeRange(k, c.step()));  // what a fleet node decodes
    EXPECT_LE(std::abs(static_cast<double>(d) - r[j]), 0.5 * c.step() + 1e-5) << r[j];
  }
  // Below 65.534 m the step is 1 mm, and an exact millimetre comes back as itself.
  const std::vector<float> mm = {0.001f, 1.234f, 12.345f, 59.999f};
  ASSERT_TRUE(c.encode(viewOf(mm, 0.0, 60.0), params10cm()));
  EXPECT_EQ(c.step(), kRangeStep);
  EXPECT_EQ(c.codes(), (std::vector<std::uint16_t>{1, 1234, 12345, 59999}));
  for (std::size_t j = 0; j < mm.size(); ++j) EXPECT_EQ(c.decoded()[j], mm[j]);
}

TEST(RangeCodec, SpecialValuesKeepTheirClass) {
  // As a LaserScan gives them: float32 limits.
  const double range_min = static_cast<double>(0.06f), range_max = 50.0;
  const std::vector<float> r = {kNan,   -kInf,   -1.0f,
                                0.0f,   -0.0f,   0.05f,  // invalid
                                kInf,   50.0f,   51.0f,
                                3e38f,  // no return
                                0.06f,  49.999f, std::nextafter(50.0f, 0.0f),
                                0.0604f};
  RangeCodec c;
  ASSERT_TRUE(c.encode(viewOf(r, range_min, range_max), params10cm()));
  EXPECT_EQ(c.step(), kRangeStep);
  for (std::size_t j = 0; j < 6; ++j) {
    EXPECT_EQ(c.codes()[j], kInvalidCode) << r[j];
    EXPECT_TRUE(std::isnan(c.decoded()[j]));
  }
  for (std::size_t j = 6; j < 10; ++j) {
    EXPECT_EQ(c.codes()[j], kNoReturnCode) << r[j];
    EXPECT_EQ(c.decoded()[j], kInf);
  }
  // Returns at the limits stay returns: range_min itself comes back at or above range_min, a
  // reading just below range_max below it (50 - 4e-6 rounds to 50 m, the first code not below
  // range_max, so it takes the last one below: 49.999 m).
  for (std::size_t j = 10; j < r.size(); ++j) {
    EXPECT_EQ(kindOf(c.decoded()[j], range_min, range_max), Kind::kReturn) << r[j];
  }
  EXPECT_EQ(c.codes()[10], 60u);
  EXPECT_GE(static_cast<double>(c.decoded()[10]), range_min);
  EXPECT_EQ(c.codes()[12], 49999u);
  EXPECT_EQ(c.codes()[13], 60u);  // 0.0604 rounds to 60 mm
  // Codes 0 and 65535 decode to NaN and +inf on every side, whatever the step.
  EXPECT_TRUE(std::isnan(decodeRange(kInvalidCode, 0.5)));
  EXPECT_EQ(decodeRange(kNoReturnCode, 0.5), kInf);
}

TEST(RangeCodec, ReachFollowsMaxRangeAndTheHardLimit) {
  // max_range below range_max: a reading between them is a no return for the core, so it is sent
  // as one, and the step stays 1 mm (the reach is 30 m).
  wavog::MapParams p = params10cm();
  p.sensor.max_range = 30.0;
  const std::vector<float> r = {29.9f, 30.0f, 45.0f};
  RangeCodec c;
  ASSERT_TRUE(c.encode(viewOf(r, 0.1, 80.0), p));
  EXPECT_EQ(c.step(), kRangeStep);
  EXPECT_EQ(c.codes(), (std::vector<std::uint16_t>{29900, kNoReturnCode, kNoReturnCode}));
  // range_max +inf (REP 117 allows it): the reach is the core's hard limit, and the step covers it.
  const std::vector<float> far(361, 500.0f);
  ASSERT_TRUE(c.encode(viewOf(far, 0.1, std::numeric_limits<double>::infinity()), params10cm()));
  const double hard = wavog::hardRangeLimit(params10cm().grid, far.size());
  EXPECT_GT(hard, 500.0);
  // Readings beyond the hard limit are possible (range_max +inf): one code is left above.
  EXPECT_DOUBLE_EQ(c.step(), hard / (kMaxHitCode - 1));
  EXPECT_NEAR(c.decoded()[0], 500.0, c.step());
  // A window of returns narrower than a step: nothing fits, the caller sends floats.
  const std::vector<float> narrow = {1.0002f};
  EXPECT_FALSE(c.encode(viewOf(narrow, 1.0001, 1.0004), params10cm()));
  EXPECT_FALSE(c.encode(viewOf(narrow, 0.0, std::nan("")), params10cm()));
}

TEST(RangeCodec, TheCoreClassifiesDecodedBeamsAsTheReadings) {
  // Random readings around every limit, through the core: the same counts of returns, invalid,
  // no-return and beyond-limit beams for the readings and for their decoded codes.
  std::mt19937 rng(3);
  const float specials[] = {kNan, kInf, -kInf, 0.0f, 0.02f, 0.0999f, 0.1f, 29.9995f, 30.0f, 79.9f};
  std::uniform_real_distribution<float> any(-1.0f, 90.0f);
  std::uniform_int_distribution<int> pick(0, 15);
  wavog::MapParams p = params10cm();
  p.sensor.max_range = 30.0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<float> r(361);
    for (float& x : r) {
      const int k = pick(rng);
      x = k < 10 ? specials[k] : any(rng);
    }
    const wavog::ScanView view = viewOf(r, 0.1, 80.0);
    RangeCodec c;
    ASSERT_TRUE(c.encode(view, p));
    wavog::WaveletMap a(p), b(p);
    const wavog::IntegrateStats sa = a.integrate(wavog::Pose2{0, 0, 0}, view);
    const wavog::IntegrateStats sb = b.integrate(wavog::Pose2{0, 0, 0}, c.decodedView(view));
    EXPECT_EQ(sa.beams_hit, sb.beams_hit);
    EXPECT_EQ(sa.beams_invalid, sb.beams_invalid);
    EXPECT_EQ(sa.beams_no_return, sb.beams_no_return);
    EXPECT_EQ(sa.beams_beyond_limit, sb.beams_beyond_limit);
  }
}

TEST(RangeCodec, ReadingsBeyondTheHardLimitStayBeyondIt) {
  // 4,000 beams at 10 cm: the core's hard limit (8,388,608 beam-cells / beams, 209.7 m) lies
  // below range_max 300 m. Readings between the two are no returns the core counts as beyond its
  // limit; their codes must decode to such readings (before: +inf, counted as plain no returns).
  const wavog::MapParams p = params10cm();
  const double hard = wavog::hardRangeLimit(p.grid, 4000);
  ASSERT_LT(hard, 300.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> any(-1.0f, 320.0f);
  std::vector<float> r(4000);
  for (float& x : r) x = any(rng);
  r[0] = static_cast<float>(hard);  // at the limit: beyond it
  r[1] = std::nextafter(300.0f, 0.0f);
  r[2] = 300.0f;  // range_max: a plain no return
  r[3] = kInf;
  const wavog::ScanView view = viewOf(r, 0.1, 300.0);
  RangeCodec c;
  ASSERT_TRUE(c.encode(view, p));
  EXPECT_NE(c.codes()[0], kNoReturnCode);
  EXPECT_NE(c.codes()[1], kNoReturnCode);
  EXPECT_EQ(c.codes()[2], kNoReturnCode);
  EXPECT_EQ(c.codes()[3], kNoReturnCode);
  wavog::WaveletMap a(p), b(p);
  const wavog::IntegrateStats sa = a.integrate(wavog::Pose2{0, 0, 0}, view);
  const wavog::IntegrateStats sb = b.integrate(wavog::Pose2{0, 0, 0}, c.decodedView(view));
  EXPECT_GT(sa.beams_beyond_limit, 500u);
  EXPECT_EQ(sa.beams_beyond_limit, sb.beams_beyond_limit);
  EXPECT_EQ(sa.beams_no_return, sb.beams_no_return);
  EXPECT_EQ(sa.beams_hit, sb.beams_hit);
  EXPECT_EQ(sa.beams_invalid, sb.beams_invalid);
}

}  // namespace
