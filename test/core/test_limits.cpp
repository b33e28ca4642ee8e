// The representable extent and the work bounds (limits.h): every fuzzing finding of issue 16 in the
// core (F1-F5, H1) as a test, plus the limits around them (block keys that would alias, beams
// beyond the hard range limit, scratch buffers, read-out sizes).
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <future>
#include <limits>
#include <string>
#include <vector>

#include "../../src/core/classify/scan_classifier.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace {

using wavog::Aggregation;
using wavog::CellBox;
using wavog::CellIndex;
using wavog::IntegrateStats;
using wavog::MapParams;
using wavog::Pose2;
using wavog::ScanStatus;
using wavog::ScanView;
using wavog::WaveletMap;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Nearly the widest band the parameters accept at `res` (kMaxBandCells cells).
double widestBandAt(double res) { return (wavog::kMaxBandCells - 0.5) * res; }

MapParams params(double res, int levels) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = res;
  p.grid.block_levels = levels;
  return p;
}

// A map file (format version 1) with two uniform observed blocks at block keys (a, a) and (b, b),
// resolution 0.25 m, block_levels 2, a valid CRC.
std::string writeFarApart(const std::string& name, std::int32_t a, std::int32_t b) {
  std::vector<unsigned char> f;
  const auto put = [&f](const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    f.insert(f.end(), c, c + n);
  };
  put("WAVOGMAP", 8);
  const std::uint32_t version = 1;
  put(&version, 4);
  const double res = 0.25, prior = 0.0, forget = 1.0;
  const std::int32_t levels = 2;
  put(&res, 8);
  put(&levels, 4);
  put(&prior, 8);
  put(&forget, 8);
  const std::uint64_t count = 2;
  put(&count, 8);
  for (const std::int32_t k : {a, b}) {
    put(&k, 4);
    put(&k, 4);
    const double s = 1.0;
    const std::uint8_t flags = 3;  // known_all | known_any, no root
    put(&s, 8);
    put(&flags, 1);
  }
  const auto crc = static_cast<std::uint32_t>(crc32(0L, f.data(), static_cast<uInt>(f.size())));
  put(&crc, 4);
  const std::string path = ::testing::TempDir() + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(f.data()), static_cast<std::streamsize>(f.size()));
  return path;
}

// Finding F1: blocks at INT32_MIN and INT32_MAX made width x height wrap to 0 at the coarsest
// scale and the read-out write through a null pointer. Such blocks lie outside the extent: the
// file is refused and the map stays as it was.
TEST(Limits, F1_MapFileWithBlocksOutsideTheExtentIsRefused) {
  WaveletMap map(params(0.25, 2));
  const std::string path = writeFarApart("f1.wavog", std::numeric_limits<std::int32_t>::min(),
                                         std::numeric_limits<std::int32_t>::max());
  try {
    map.load(path);
    FAIL() << "loaded a file with blocks outside the extent";
  } catch (const wavog::MapIoError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the representable extent"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(map.stats().blocks, 0u);
  CellBox box;
  EXPECT_FALSE(map.bounds(2, &box));
}

// The extent's edge itself loads; its bounds are too large to read out at any scale, and the
// refusal is a ReadoutTooLarge, not an allocation.
TEST(Limits, F1_BlocksAtTheEdgesOfTheExtentLoadAndTheirReadOutIsRefused) {
  WaveletMap map(params(0.25, 2));
  const std::int32_t edge = static_cast<std::int32_t>(wavog::kCellIndexLimit >> 2);
  map.load(writeFarApart("f1_edge.wavog", -edge, edge - 1));
  EXPECT_EQ(map.stats().blocks, 2u);
  EXPECT_TRUE(map.isObserved(CellIndex{-wavog::kCellIndexLimit, -wavog::kCellIndexLimit}));
  EXPECT_TRUE(map.isObserved(CellIndex{wavog::kCellIndexLimit - 1, wavog::kCellIndexLimit - 1}));
  for (int s = 0; s <= 2; ++s) {
    CellBox box;
    ASSERT_TRUE(map.bounds(s, &box));
    EXPECT_FALSE(wavog::readoutFits(box)) << "scale " << s;
    EXPECT_THROW(map.exportScale(s, box, Aggregation::kMean), wavog::ReadoutTooLarge);
  }
  // A window around one of the blocks reads out.
  const wavog::Raster r =
      map.exportScale(0,
                      CellBox{-wavog::kCellIndexLimit, -wavog::kCellIndexLimit,
                              -wavog::kCellIndexLimit + 8, -wavog::kCellIndexLimit + 8},
                      Aggregation::kMean);
  ASSERT_EQ(r.known.size(), 64u);
  EXPECT_EQ(r.known[0], 1);
  EXPECT_EQ(r.known[63], 0);
}

// Finding F2: blocks 2^20 apart made the read-out of the bounds ask for 2^46 bytes (bad_alloc or
// length_error). Now a ReadoutTooLarge, with the window's size in its message.
TEST(Limits, F2_ReadOutAboveTheCellLimitIsRefusedWithoutAllocating) {
  WaveletMap map(params(0.25, 2));
  map.load(writeFarApart("f2.wavog", 0, 1 << 20));
  CellBox box;
  ASSERT_TRUE(map.bounds(0, &box));
  const std::uint64_t side = (std::uint64_t{1} << 22) + 4;  // cells 0 .. 2^22 + 3
  EXPECT_EQ(wavog::readoutCells(box), side * side);
  EXPECT_FALSE(wavog::readoutFits(box));
  try {
    (void)map.exportScale(0, box, Aggregation::kMean);
    FAIL() << "read out " << wavog::readoutCells(box) << " cells";
  } catch (const wavog::ReadoutTooLarge& e) {
    EXPECT_NE(std::string(e.what()).find("4194308 x 4194308"), std::string::npos) << e.what();
  }
}

TEST(Limits, ReadoutCellsIsExactAndSaturates) {
  constexpr auto kMin = std::numeric_limits<std::int64_t>::min();
  constexpr auto kMax = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(wavog::readoutCells(CellBox{0, 0, 0, 5}), 0u);
  EXPECT_EQ(wavog::readoutCells(CellBox{-3, -2, 5, 2}), 32u);
  EXPECT_EQ(wavog::readoutCells(CellBox{kMin, 0, kMax, 1}),
            std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(wavog::readoutCells(CellBox{kMin, kMin, kMax, kMax}),
            std::numeric_limits<std::uint64_t>::max());
  EXPECT_TRUE(wavog::readoutFits(CellBox{0, 0, 8192, 8192}));
  EXPECT_FALSE(wavog::readoutFits(CellBox{0, 0, 8192, 8193}));
  WaveletMap map(params(0.05, 4));
  EXPECT_THROW(map.exportScale(0, CellBox{kMin, kMin, kMax, kMax}, Aggregation::kMax),
               wavog::ReadoutTooLarge);
}

// Finding F3: a finite pose whose hit cells are beyond int64 (a float-to-int cast of inf). Now
// refused as out of the extent, and so is a room 2^32 blocks away that a 32-bit block key would
// have put at the origin.
TEST(Limits, F3_PoseOutsideTheExtentIsRefused) {
  WaveletMap map(params(0.01, 6));
  const std::vector<float> ranges = {2.0f, 3.0f};
  const ScanView scan{ranges.data(), ranges.size(), 0.0, 0.1, 0.0, 60.0};
  IntegrateStats st = map.integrate(Pose2{13.9, 1.6e308, 1.2}, scan);
  EXPECT_EQ(st.status, ScanStatus::kOutOfExtent);
  const double block = std::ldexp(0.01, 6);
  st = map.integrate(Pose2{std::ldexp(block, 32), 0.0, 0.0}, scan);
  EXPECT_EQ(st.status, ScanStatus::kOutOfExtent);
  EXPECT_EQ(map.stats().blocks, 0u);
  EXPECT_STREQ(wavog::toString(ScanStatus::kOutOfExtent), "out_of_extent");
}

TEST(Limits, PoseNearTheEdgeOfTheExtentIsMappedThere) {
  WaveletMap map(params(0.01, 6));
  const std::vector<float> ranges = {2.0f};
  const ScanView scan{ranges.data(), ranges.size(), 0.0, 0.1, 0.0, 2.5};
  // The pose plus the range limit (2.5 m) and half a cell must stay 2 cells inside the extent.
  const double edge = static_cast<double>(wavog::kCellIndexLimit) * 0.01;
  EXPECT_EQ(map.integrate(Pose2{edge - 2.52, 0.0, 0.0}, scan).status, ScanStatus::kOutOfExtent);
  const double x = edge - 2.6;
  const IntegrateStats st = map.integrate(Pose2{x, 0.0, 0.0}, scan);
  ASSERT_EQ(st.status, ScanStatus::kOk);
  const CellIndex hit = map.cellAt(x + 2.0, 0.0);
  EXPECT_TRUE(map.isObserved(hit));
  EXPECT_GT(map.value(hit), 0.0f);
  EXPECT_LT(st.touched.max_x, wavog::kCellIndexLimit);
}

// A cell beyond the extent has no block, though its 32-bit block key would name one.
TEST(Limits, CellsOutsideTheExtentAreNeverObserved) {
  WaveletMap map(params(0.05, 4));
  const std::vector<float> ranges = {1.0f};
  const ScanView scan{ranges.data(), ranges.size(), 0.0, 0.1, 0.0, 60.0};
  ASSERT_EQ(map.integrate(Pose2{}, scan).status, ScanStatus::kOk);
  const CellIndex hit = map.cellAt(1.0, 0.0);
  ASSERT_TRUE(map.isObserved(hit));
  const std::int64_t alias = std::int64_t{1} << (32 + 4);  // 2^32 blocks of 2^4 cells
  EXPECT_FALSE(map.isObserved(CellIndex{hit.x + alias, hit.y}));
  EXPECT_EQ(map.value(CellIndex{hit.x + alias, hit.y}), map.value(CellIndex{-5, 40}));
  // Far points give clamped cells, not overflowing casts.
  EXPECT_EQ(map.cellAt(1e300, -kInf).x, wavog::kCellIndexLimit);
  EXPECT_EQ(map.cellAt(1e300, -kInf).y, -wavog::kCellIndexLimit - 1);
  EXPECT_EQ(map.cellAt(std::nan(""), 0.0).x, wavog::kCellIndexLimit);
  const CellBox far = map.boxAround(-1e300, -kInf, 1e300, kInf, 0);
  EXPECT_EQ(far.min_x, -wavog::kCellIndexLimit - 1);
  EXPECT_EQ(far.max_y, wavog::kCellIndexLimit + 1);
  EXPECT_TRUE(map.boxAround(std::nan(""), 0, 1, 1, 0).empty());
}

// Finding F4: clearBox with bounds of +-1e19 at 0.05 m was a float-to-int cast with undefined
// result, which cleared nothing and still returned. Now it clears the whole map and says so.
TEST(Limits, F4_ClearBoxWithHugeBoundsClearsEverything) {
  WaveletMap map(params(0.05, 8));
  const std::vector<float> ranges = {2.0f, 3.0f};
  const ScanView scan{ranges.data(), ranges.size(), 0.0, 0.1, 0.0, 60.0};
  ASSERT_EQ(map.integrate(Pose2{0, 0, 0}, scan).status, ScanStatus::kOk);
  ASSERT_EQ(map.integrate(Pose2{-40, -30, 2}, scan).status, ScanStatus::kOk);
  const std::size_t blocks = map.stats().blocks;
  ASSERT_GE(blocks, 2u);
  EXPECT_EQ(map.clearBox(-1e19, -1e19, 1e19, 1e19), blocks);
  EXPECT_EQ(map.stats().blocks, 0u);
  ASSERT_EQ(map.integrate(Pose2{0, 0, 0}, scan).status, ScanStatus::kOk);
  EXPECT_EQ(map.clearBox(std::nan(""), -1, 1, 1), 0u);
  EXPECT_EQ(map.clearBox(1e19, 1e19, kInf, kInf), 0u);  // beyond the extent: nothing there
  EXPECT_GT(map.stats().blocks, 0u);
  EXPECT_GT(map.clearBox(-kInf, -kInf, kInf, kInf), 0u);
  EXPECT_EQ(map.stats().blocks, 0u);
}

// Finding F5: a finite angle_min of 1.1e308 made the bearing arithmetic inf - inf and cast the
// NaN to an index. angle_min and angle_increment have documented limits now.
TEST(Limits, F5_AbsurdAnglesAreBadGeometry) {
  WaveletMap map(params(0.05, 5));
  const std::vector<float> ranges = {1.0f, 1.5f, 2.0f};
  ScanView scan{ranges.data(), ranges.size(), 1.1491136509119899e308, 0.0278, 0.0, 10.0};
  EXPECT_EQ(map.integrate(Pose2{0.5, 0.5, 1.9}, scan).status, ScanStatus::kBadGeometry);
  scan.angle_min = -wavog::kMaxAbsAngleMin * 1.01;
  EXPECT_EQ(map.integrate(Pose2{0.5, 0.5, 1.9}, scan).status, ScanStatus::kBadGeometry);
  scan.angle_min = 0.0;
  scan.angle_increment = -0.5 * wavog::kMinAbsAngleIncrement;
  EXPECT_EQ(map.integrate(Pose2{0.5, 0.5, 1.9}, scan).status, ScanStatus::kBadGeometry);
  scan.angle_increment = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(map.integrate(Pose2{0.5, 0.5, 1.9}, scan).status, ScanStatus::kBadGeometry);
  EXPECT_EQ(map.stats().blocks, 0u);
  // Just inside the limits, the scan is mapped.
  scan.angle_min = 0.99 * wavog::kMaxAbsAngleMin;
  scan.angle_increment = 0.0278;
  EXPECT_EQ(map.integrate(Pose2{0.5, 0.5, 1.9}, scan).status, ScanStatus::kOk);
  EXPECT_GT(map.stats().blocks, 0u);
}

// Finding H1: one beam of 1e7 m with range_max +inf made the block loop cover (2 reach / block
// size)^2 blocks. A reading at or beyond the hard range limit is a no return.
TEST(Limits, H1_BeamBeyondTheHardRangeLimitIsANoReturn) {
  WaveletMap map(params(0.05, 9));
  for (const float z : {1e7f, std::numeric_limits<float>::max()}) {
    const std::vector<float> ranges = {z};
    const ScanView scan{ranges.data(), ranges.size(), 0.0, 0.01, 0.0, kInf};
    auto done = std::async(std::launch::async, [&] { return map.integrate(Pose2{0, 0, 0}, scan); });
    ASSERT_EQ(done.wait_for(std::chrono::seconds(120)), std::future_status::ready)
        << "integrate() still running after 120 s";
    const IntegrateStats st = done.get();
    EXPECT_EQ(st.status, ScanStatus::kNoValidBeam) << z;  // no return, no clearing configured
    EXPECT_EQ(st.beams_hit, 0u) << z;
    EXPECT_EQ(st.beams_no_return, 1u) << z;
    EXPECT_EQ(st.beams_beyond_limit, 1u) << z;
  }
  EXPECT_EQ(map.stats().blocks, 0u);
}

// The hard limit caps no_return_clear as well, and bounds the cells and blocks a scan touches.
TEST(Limits, HardRangeLimitCapsClearingAndBoundsTheWork) {
  MapParams p = params(0.05, 2);  // small blocks: the block limit binds (256 blocks of 4 cells)
  p.sensor.no_return_clear = 1e6;
  const double hard = wavog::hardRangeLimit(p.grid, 2);
  EXPECT_DOUBLE_EQ(hard, 256.0 * 4.0 * 0.05);
  EXPECT_DOUBLE_EQ(wavog::hardRangeLimit(params(0.05, 9).grid, 1), 65536.0 * 0.05);
  EXPECT_DOUBLE_EQ(wavog::hardRangeLimit(params(0.05, 9).grid, 4096), 2048.0 * 0.05);
  WaveletMap map(p);
  const std::vector<float> ranges = {std::numeric_limits<float>::infinity(), 150.0f};
  const ScanView scan{ranges.data(), ranges.size(), 0.0, 0.001, 0.0, kInf};
  const IntegrateStats st = map.integrate(Pose2{}, scan);
  ASSERT_EQ(st.status, ScanStatus::kOk);
  EXPECT_EQ(st.beams_no_return, 2u);
  EXPECT_EQ(st.beams_beyond_limit, 1u);  // 150 m is beyond 51.2 m; +inf is a no return anyway
  EXPECT_TRUE(map.isObserved(map.cellAt(hard - 1.0, 0.0)));
  EXPECT_FALSE(map.isObserved(map.cellAt(hard + 1.0, 0.0)));
  const auto side = static_cast<std::int64_t>(2.0 * hard / 0.05) + 3;
  EXPECT_LE(st.touched.width(), side);
  EXPECT_LE(st.touched.height(), side);
  const double blocks_side = 2.0 * wavog::kMaxRangeBlocks + 2.0;
  EXPECT_LE(static_cast<double>(st.blocks_touched), blocks_side * blocks_side);
}

// The tree work of one scan is bounded by its beams times the hard range limit in cells: random
// ranges up to the limit (the costliest scans measured, about 1.5 nodes per beam-cell) stay well
// below 4 nodes per beam-cell of kMaxScanBeamCells.
TEST(Limits, WorkOfTheCostliestScanIsBounded) {
  const MapParams p = params(0.05, 9);
  const std::size_t beams = 1081;
  const double hard = wavog::hardRangeLimit(p.grid, beams);
  EXPECT_NEAR(hard / 0.05, wavog::kMaxScanBeamCells / static_cast<double>(beams), 1e-6);
  std::vector<float> ranges(beams);
  std::uint64_t state = 12345;
  for (float& z : ranges) {  // xorshift: uniform in (0, 0.999 hard)
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    z = static_cast<float>(0.999 * hard * static_cast<double>(state >> 11) * 0x1.0p-53) + 0.01f;
  }
  WaveletMap map(p);
  const ScanView scan{ranges.data(), ranges.size(), -2.35, 4.7 / static_cast<double>(beams),
                      0.0,           kInf};
  const IntegrateStats st = map.integrate(Pose2{}, scan);
  ASSERT_EQ(st.status, ScanStatus::kOk);
  EXPECT_EQ(st.beams_hit, beams);
  EXPECT_GT(st.nodes_visited, 1000000u);  // the case is costly indeed
  EXPECT_LE(static_cast<double>(st.nodes_visited), 4.0 * wavog::kMaxScanBeamCells);
}

// Issue 42, item 4: a wide occupied band is walked cell by cell, so its cells count against the
// same budget (hardRangeLimit(params, beams, increment)). At 1.01 mm with every beam returning just
// inside the hard limit, a band of 0.3 m took 1.85e8 nodes per scan and one of 10 m 1.83e9; now
// every scan stays within the bound of a one-cell band, and a band of more than kMaxBandCells
// cells is refused by the parameters, naming band_width and resolution.
TEST(Limits, WideBandKeepsTheWorkOfAScanBounded) {
  const double res = 1.01e-3, pi = 3.14159265358979323846;
  struct Fan {
    std::size_t beams;
    double fov;
  };
  const Fan fans[] = {{361, pi}, {1081, 1.5 * pi}, {3600, 2 * pi}, {8, 2 * pi}};
  std::uint64_t worst_band0 = 0;
  for (const double band : {0.0, 0.3, widestBandAt(res)}) {
    MapParams p = params(res, 9);
    p.sensor.band_width = band;
    ASSERT_TRUE(p.validate().empty()) << band;
    for (const Fan& f : fans) {
      const double inc = f.fov / static_cast<double>(f.beams);
      const double hard = wavog::hardRangeLimit(p, f.beams, inc);
      EXPECT_LE(hard, wavog::hardRangeLimit(p.grid, f.beams));
      if (band == 0.0) {
        EXPECT_EQ(hard, wavog::hardRangeLimit(p.grid, f.beams));
      }
      const std::vector<float> ranges(f.beams, static_cast<float>(0.999 * hard));
      WaveletMap map(p);
      const ScanView scan{ranges.data(), ranges.size(), -0.5 * f.fov, inc, 0.0, kInf};
      const IntegrateStats st = map.integrate(Pose2{0.3, -0.2, 0.1}, scan);
      ASSERT_EQ(st.status, ScanStatus::kOk);
      EXPECT_EQ(st.beams_hit, f.beams) << band;  // every return inside the limit maps
      std::printf("band_width %.4g m, %zu beams over %.3g rad: hard limit %.4g m, %llu nodes\n",
                  band, f.beams, f.fov, hard, static_cast<unsigned long long>(st.nodes_visited));
      if (band == 0.0) worst_band0 = std::max(worst_band0, st.nodes_visited);
      EXPECT_LE(static_cast<double>(st.nodes_visited), 2.0 * wavog::kMaxScanBeamCells)
          << "band_width " << band << ", " << f.beams << " beams";
      EXPECT_EQ(map.stats().nodes_visited_last, st.nodes_visited);
    }
  }
  EXPECT_GT(worst_band0, 1000000u);  // the scans are costly indeed
  // The allowed maximum of band_width, 10 m, is refused at this resolution, naming both.
  MapParams wide = params(res, 9);
  wide.sensor.band_width = 10.0;
  const auto errors = wide.validate();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("band_width"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("resolution"), std::string::npos) << errors[0];
  EXPECT_THROW(WaveletMap{wide}, std::invalid_argument);
}

// Scratch buffers grown by one absurd scan are released; ordinary ones are kept for reuse.
TEST(Limits, LargeScanScratchIsReleased) {
  const MapParams p = params(0.05, 9);
  wavog::detail::ScanClassifier cls;
  IntegrateStats st;
  std::vector<float> small(1000, 5.0f);
  ASSERT_EQ(
      cls.prepare(p, Pose2{}, ScanView{small.data(), small.size(), -3.0, 0.006, 0.0, 30.0}, &st),
      ScanStatus::kOk);
  cls.releaseIfLarge();
  EXPECT_GE(cls.scan().kind.capacity(), 1000u);
  std::vector<float> large(wavog::kScratchKeepBeams + 1, 5.0f);
  const double inc = 6.0 / static_cast<double>(large.size());
  ASSERT_EQ(
      cls.prepare(p, Pose2{}, ScanView{large.data(), large.size(), -3.0, inc, 0.0, 30.0}, &st),
      ScanStatus::kOk);
  cls.releaseIfLarge();
  EXPECT_EQ(cls.scan().kind.capacity(), 0u);
  EXPECT_EQ(cls.scan().min_e2.capacity(), 0u);
  EXPECT_EQ(cls.scan().bnd_x.capacity(), 0u);
  // And the classifier still works afterwards.
  WaveletMap map(p);
  EXPECT_EQ(
      map.integrate(Pose2{}, ScanView{large.data(), large.size(), -3.0, inc, 0.0, 30.0}).status,
      ScanStatus::kOk);
  EXPECT_EQ(
      map.integrate(Pose2{}, ScanView{small.data(), small.size(), -3.0, 0.006, 0.0, 30.0}).status,
      ScanStatus::kOk);
}

// Motion compensation passes a scan with more beams than the core takes through untouched: it
// reads no beam of it and allocates nothing for it.
TEST(Limits, MotionCompensationPassesOversizedScansThrough) {
  const std::vector<float> few = {1.0f, 2.0f};
  // count exceeds the buffer on purpose: none of it may be read.
  const ScanView huge{few.data(), wavog::kMaxBeams + 1, 0.0, 1e-7, 0.0, 10.0};
  wavog::MotionCompensator mc;
  const ScanView out = mc.compensate(huge, Pose2{}, Pose2{1, 0, 0}, Pose2{});
  EXPECT_EQ(out.ranges, few.data());
  EXPECT_EQ(out.count, huge.count);
  EXPECT_EQ(mc.droppedLast(), 0u);
}

}  // namespace
