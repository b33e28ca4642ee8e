// The scan classifier alone, without a map, against the dense reference's cell-by-cell model:
// every cell's class exact, every square's class conservative (E only if all its cells are E, U
// only if all are U, FREE_OR_UNKNOWN only without O), the 4 x 4 and 8 x 8 groups exact, on seeded
// random scans with every kind of bad beam (NaN, +-inf, 0, below range_min, beyond range_max).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include "../../src/core/classify/scan_classifier.h"
#include "../../src/core/classify/sector_table.h"
#include "dense_reference.h"
#include "test_support.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_test {
namespace {

using wavog::CellClass;
using wavog::detail::CellMasks;
using wavog::detail::ScanClassifier;
using wavog::detail::SquareInfo;
using wavog::detail::TileMasks;

// Counts of what the walk checked, so the test cannot pass by checking nothing.
struct Seen {
  std::array<std::size_t, 5> squares{};  // by CellClass
  std::array<std::size_t, 3> cells{};    // U, E, O
  std::size_t groups_4x4 = 0;
  std::size_t groups_8x8 = 0;
};

class Walk {
 public:
  Walk(const ScanClassifier& c, const ReferenceClassifier& r, Seen* seen)
      : cls_(c), ref_(r), seen_(seen) {}

  // Checks the square of side 2^l at (ix0, iy0) classified as `info`, then its sub-squares
  // classified from it (as the integration does), down to its cells.
  void square(int l, std::int64_t ix0, std::int64_t iy0, const SquareInfo& info) {
    ++seen_->squares[static_cast<std::size_t>(info.cls)];
    expectConservative(l, ix0, iy0, info.cls);
    if (info.cls == CellClass::kUnknown || ::testing::Test::HasFailure()) return;
    if (l == 1) {
      for (int q = 0; q < 4; ++q) {
        const std::int64_t x = ix0 + (q & 1), y = iy0 + (q >> 1);
        const CellClass want = ref_.cellClass(x, y);
        ++seen_->cells[want == CellClass::kUnknown ? 0 : want == CellClass::kEmpty ? 1 : 2];
        ASSERT_EQ(cls_.classifyCell(x, y, info), want) << "cell (" << x << ", " << y << ")";
      }
      return;
    }
    if (l == 2 && ScanClassifier::fewSectors(info)) expect4x4(ix0, iy0, info);
    if (l == 3) expectTile(ix0, iy0, info);
    const std::int64_t half = std::int64_t{1} << (l - 1);
    for (int q = 0; q < 4; ++q) {
      const std::int64_t cx = ix0 + ((q & 1) ? half : 0), cy = iy0 + ((q & 2) ? half : 0);
      square(l - 1, cx, cy, cls_.classifySquare(l - 1, cx, cy, info));
    }
  }

 private:
  void expectConservative(int l, std::int64_t ix0, std::int64_t iy0, CellClass cls) {
    const std::int64_t size = std::int64_t{1} << l;
    for (std::int64_t y = iy0; y < iy0 + size; ++y) {
      for (std::int64_t x = ix0; x < ix0 + size; ++x) {
        const CellClass c = ref_.cellClass(x, y);
        const bool ok = cls == CellClass::kMixed ||
                        (cls == CellClass::kEmpty && c == CellClass::kEmpty) ||
                        (cls == CellClass::kUnknown && c == CellClass::kUnknown) ||
                        (cls == CellClass::kFreeOrUnknown && c != CellClass::kOccupied);
        ASSERT_TRUE(ok) << "square l=" << l << " at (" << ix0 << ", " << iy0 << ") class "
                        << static_cast<int>(cls) << " holds cell (" << x << ", " << y
                        << ") of class " << static_cast<int>(c);
      }
    }
  }

  void expect4x4(std::int64_t ix0, std::int64_t iy0, const SquareInfo& info) {
    ++seen_->groups_4x4;
    expectGroup(ix0, iy0, cls_.classify4x4(ix0, iy0, info));
  }

  // classifyTileCells: the 64 cells of a tile (as the walk updates them), by row runs where
  // they lie in few sectors, else by groups or cells.
  void expectTile(std::int64_t ix0, std::int64_t iy0, const SquareInfo& info) {
    if (ScanClassifier::fewSectors(info)) ++seen_->groups_8x8;
    const TileMasks m = cls_.classifyTileCells(3, ix0, iy0, info);
    expectCells("tile", ix0, iy0, 3, m.e, m.o);
  }

  void expectGroup(std::int64_t ix0, std::int64_t iy0, const CellMasks& m) {
    expectCells("4x4", ix0, iy0, 2, m.e, m.o);
  }

  // The cells of the square of side 2^bits at (ix0, iy0), cell (x, y) at bit x + 2^bits y of the
  // masks e (E) and o (O), against the reference.
  void expectCells(const char* what, std::int64_t ix0, std::int64_t iy0, unsigned bits,
                   std::uint64_t e, std::uint64_t o) {
    const unsigned side = 1u << bits;
    for (unsigned i = 0; i < side * side; ++i) {
      const std::int64_t x = ix0 + (i & (side - 1)), y = iy0 + (i >> bits);
      const CellClass want = ref_.cellClass(x, y);
      const CellClass got = ((e >> i) & 1u)   ? CellClass::kEmpty
                            : ((o >> i) & 1u) ? CellClass::kOccupied
                                              : CellClass::kUnknown;
      ASSERT_FALSE(((e >> i) & 1u) && ((o >> i) & 1u)) << "cell both E and O";
      ASSERT_EQ(got, want) << what << " at (" << ix0 << ", " << iy0 << "), cell (" << x << ", " << y
                           << ")";
    }
  }

  const ScanClassifier& cls_;
  const ReferenceClassifier& ref_;
  Seen* seen_;
};

constexpr int kWalkLevels = 5;

// One scan: the classifier against the reference on every square of side 2^kWalkLevels within
// its reach (plus one square of margin), down to every cell. False when both refuse it.
bool checkScan(const wavog::MapParams& p, const OwnedScan& s, ScanClassifier* cls,
               ReferenceClassifier* ref, Seen* seen) {
  const std::int64_t size = std::int64_t{1} << kWalkLevels;
  wavog::IntegrateStats st;
  const wavog::ScanStatus status = cls->prepare(p, s.pose, s.view(), &st);
  const bool ref_ok = ref->prepare(p, s.pose, s.view());
  EXPECT_EQ(status == wavog::ScanStatus::kOk, ref_ok);
  if (!ref_ok || status != wavog::ScanStatus::kOk) return false;
  EXPECT_EQ(st.beams_hit + st.beams_no_return + st.beams_invalid, s.ranges.size());
  const double reach = ref->reach() + size * p.grid.resolution;
  const auto lo_x =
      static_cast<std::int64_t>(std::floor((s.pose.x - reach) / p.grid.resolution)) / size - 1;
  const auto hi_x =
      static_cast<std::int64_t>(std::floor((s.pose.x + reach) / p.grid.resolution)) / size + 1;
  const auto lo_y =
      static_cast<std::int64_t>(std::floor((s.pose.y - reach) / p.grid.resolution)) / size - 1;
  const auto hi_y =
      static_cast<std::int64_t>(std::floor((s.pose.y + reach) / p.grid.resolution)) / size + 1;
  Walk walk(*cls, *ref, seen);
  for (std::int64_t by = lo_y; by <= hi_y; ++by) {
    for (std::int64_t bx = lo_x; bx <= hi_x; ++bx) {
      walk.square(kWalkLevels, bx * size, by * size,
                  cls->classifySquare(kWalkLevels, bx * size, by * size));
      if (::testing::Test::HasFailure()) return true;
    }
  }
  return true;
}

void checkScans(const wavog::MapParams& p, std::uint32_t seed, int count, Seen* seen) {
  const double half = 8.0;
  RandomScans scans(seed, half);
  ScanClassifier cls;
  ReferenceClassifier ref;
  for (int i = 0; i < count; ++i) {
    checkScan(p, scans.next(), &cls, &ref, seen);
    ASSERT_FALSE(::testing::Test::HasFailure()) << "scan " << i;
  }
}

void expectEveryClassSeen(const Seen& seen, const std::string& what) {
  EXPECT_GT(seen.squares[static_cast<std::size_t>(CellClass::kUnknown)], 0u) << what;
  EXPECT_GT(seen.squares[static_cast<std::size_t>(CellClass::kEmpty)], 0u) << what;
  EXPECT_GT(seen.squares[static_cast<std::size_t>(CellClass::kMixed)], 0u) << what;
  EXPECT_GT(seen.cells[0], 0u) << what;
  EXPECT_GT(seen.cells[1], 0u) << what;
  EXPECT_GT(seen.cells[2], 0u) << what;
  EXPECT_GT(seen.groups_4x4, 0u) << what;
  EXPECT_GT(seen.groups_8x8, 0u) << what;
}

TEST(ScanClassifier, RandomScansMatchTheCellByCellReference) {
  wavog::MapParams p;
  p.grid.resolution = 0.1;
  Seen seen;
  checkScans(p, 77u, 120, &seen);
  expectEveryClassSeen(seen, "default sensor model");
}

TEST(ScanClassifier, ClearingNoReturnsWideBandAndMaxRange) {
  wavog::MapParams p;
  p.grid.resolution = 0.1;
  p.sensor.no_return_clear = 2.5;  // no-return beams clear free space: FREE_OR_UNKNOWN squares
  p.sensor.band_width = 0.35;
  p.sensor.max_range = 2.8;  // some returns beyond it count as no return
  Seen seen;
  checkScans(p, 4242u, 120, &seen);
  expectEveryClassSeen(seen, "clearing");
  EXPECT_GT(seen.squares[static_cast<std::size_t>(CellClass::kFreeOrUnknown)], 0u);
}

// Scans taken from the lattice of cells (issue 42): the sensor on a cell centre (its own cell's
// offset is (0, 0), whose bearing the reference takes as atan2(0, 0) = 0 in the map frame), on a
// cell edge or a corner; headings on multiples of pi / 4 (also a turn off) and random; fans of a
// few wide beams, fans with a sector boundary along an axis or a diagonal of the lattice (through
// cell centres), and fans with a beam along one. Simulated and quantised poses sit there.
class LatticeScans {
 public:
  LatticeScans(std::uint32_t seed, double res) : rng_(seed), res_(res) {}

  OwnedScan next() {
    OwnedScan s;
    const int kind = count_++ % 4;  // centre / centre x, edge y / edge x, centre y / corner
    const auto at = [&](bool centre) {
      const double i = static_cast<double>(index(rng_));
      return centre ? (i + 0.5) * res_ : i * res_;  // as the classifier computes a cell centre
    };
    s.pose.x = at(kind == 0 || kind == 1);
    s.pose.y = at(kind == 0 || kind == 2);
    const double eighth = static_cast<double>(eighths(rng_)) * kPi / 4;
    const double pick = unit(rng_);
    s.pose.theta = pick < 0.5    ? eighth
                   : pick < 0.7  ? eighth + (unit(rng_) < 0.5 ? -2 : 2) * kPi
                   : pick < 0.85 ? eighth + 0.0086
                                 : (unit(rng_) - 0.5) * 2 * kPi;
    const double along = static_cast<double>(eighths(rng_)) * kPi / 4;  // sensor frame
    const int fan = static_cast<int>(unit(rng_) * 3);
    int n;
    if (fan == 0) {  // a few wide beams anywhere
      n = 1 + static_cast<int>(unit(rng_) * 4);
      const double steps[] = {0.01, 0.02, 0.1, 0.3, 1.0, 2 * kPi / n};
      s.angle_increment = steps[static_cast<int>(unit(rng_) * 6)];
      s.angle_min = (unit(rng_) - 0.5) * 2 * kPi;
    } else {  // a boundary (fan 1) or a beam (fan 2) along a lattice direction
      n = 8 + static_cast<int>(unit(rng_) * 400);
      const double fovs[] = {2 * kPi, 1.5 * kPi, kPi, 0.5 * kPi};
      s.angle_increment = fovs[static_cast<int>(unit(rng_) * 4)] / n;
      const double k = std::floor(unit(rng_) * n);
      s.angle_min = along - (k + (fan == 1 ? 0.5 : 0.0)) * s.angle_increment;
    }
    if (unit(rng_) < 0.3) {  // the same beams, listed clockwise
      s.angle_min += (n - 1) * s.angle_increment;
      s.angle_increment = -s.angle_increment;
    }
    s.range_min = 0.02;
    s.range_max = 3.0;
    s.ranges.resize(static_cast<std::size_t>(n));
    for (auto& z : s.ranges) {
      const double r = unit(rng_);
      z = r < 0.05   ? std::numeric_limits<float>::quiet_NaN()
          : r < 0.1  ? std::numeric_limits<float>::infinity()
          : r < 0.15 ? 0.01f
                     : static_cast<float>(0.05 + 2.9 * unit(rng_));
    }
    // Half of the fans of one beam: the 0.8 m return.
    if (n == 1 && unit(rng_) < 0.5) s.ranges[0] = 0.8f;
    return s;
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;
  std::mt19937 rng_;
  double res_;
  int count_ = 0;
  std::uniform_int_distribution<int> index{-40, 40};
  std::uniform_int_distribution<int> eighths{-8, 8};
  std::uniform_real_distribution<double> unit{0.0, 1.0};
};

// Issue 42: the sensor exactly on a cell centre, theta pi / 4, one beam at -0.0086 rad whose
// sector holds sensor bearing 0 but not the reference's -pi / 4 for the offset (0, 0). The core
// wrote the sensor's own cell E (-0.4) where the reference leaves it U.
TEST(ScanClassifier, SensorOnACellCentreKeepsTheReferencesClassOfItsCell) {
  wavog::MapParams p = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = 0.05;
  const float range = 0.8f;
  const wavog::Pose2 pose{0.275, -0.275, 3.14159265358979323846 / 4};
  ASSERT_EQ((5 + 0.5) * p.grid.resolution, pose.x);  // exactly the centre of cell (5, -6)
  ASSERT_EQ((-6 + 0.5) * p.grid.resolution, pose.y);
  for (const double inc : {0.1, 0.5, 1.0, -0.1}) {
    const wavog::ScanView view{&range, 1, -0.0086, inc, 0.0, 10.0};
    ReferenceClassifier ref;
    ASSERT_TRUE(ref.prepare(p, pose, view));
    ASSERT_EQ(ref.cellClass(5, -6), CellClass::kUnknown) << "increment " << inc;
    ScanClassifier cls;
    Seen seen;
    ASSERT_TRUE(checkScan(p, OwnedScan{pose, {range}, -0.0086, inc, 0.0, 10.0}, &cls, &ref, &seen))
        << "increment " << inc;
    ASSERT_FALSE(::testing::Test::HasFailure()) << "increment " << inc;
    // The map: the sensor's cell stays unobserved at the prior, the reference's cells agree.
    wavog::WaveletMap map(p);
    DenseReference dense(p, wavog::CellBox{-40, -40, 40, 40});
    map.integrate(pose, view);
    dense.integrate(pose, view);
    EXPECT_FALSE(map.isObserved({5, -6})) << "increment " << inc;
    EXPECT_EQ(map.value({5, -6}), dense.value(5, -6)) << "increment " << inc;
    const Comparison c = compare(map, dense);
    EXPECT_EQ(c.knowledge_mismatches, 0u) << "increment " << inc;
    EXPECT_LE(c.max_rel_error, 1e-4) << "increment " << inc;
  }
}

// Many such poses, every cell of every square within reach (classifier alone), at three
// resolutions (0.0625: cell centres and edges exact in binary) and with a wide band and clearing
// no-returns.
TEST(ScanClassifier, LatticePosesMatchTheCellByCellReference) {
  std::size_t sensor_on_centre = 0;
  for (const double res : {0.05, 0.1, 0.0625}) {
    for (const bool wide : {false, true}) {
      wavog::MapParams p;
      p.grid.resolution = res;
      if (wide) {
        p.sensor.band_width = 0.3;
        p.sensor.no_return_clear = 2.0;
      }
      LatticeScans scans(wide ? 4201u : 42u, res);
      ScanClassifier cls;
      ReferenceClassifier ref;
      Seen seen;
      for (int i = 0; i < 200; ++i) {
        const OwnedScan s = scans.next();
        if (!checkScan(p, s, &cls, &ref, &seen)) continue;
        ASSERT_FALSE(::testing::Test::HasFailure())
            << "resolution " << res << " scan " << i << " pose (" << s.pose.x << ", " << s.pose.y
            << ", " << s.pose.theta << ") angle_min " << s.angle_min << " increment "
            << s.angle_increment << ", " << s.ranges.size() << " beams";
        if (i % 4 == 0) ++sensor_on_centre;
      }
      expectEveryClassSeen(seen, "lattice poses");
    }
  }
  EXPECT_GT(sensor_on_centre, 250u);  // of 300 scans from a cell centre
}

// The same scans integrated into maps against the dense reference (every policy's path through
// the walk: single-beam squares, 4 x 4 and 8 x 8 groups, leaf parents).
TEST(ScanClassifier, LatticePosesGiveTheReferencesMap) {
  for (const double res : {0.05, 0.0625}) {
    wavog::MapParams p = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
    p.grid.resolution = res;
    p.grid.block_levels = 4;
    const auto half = static_cast<std::int64_t>(std::ceil(5.5 / res));
    wavog::WaveletMap map(p);
    DenseReference dense(p, wavog::CellBox{-half, -half, half, half});
    LatticeScans scans(7u, res);
    for (int i = 0; i < 120; ++i) {
      const OwnedScan s = scans.next();
      map.integrate(s.pose, s.view());
      dense.integrate(s.pose, s.view());
      const Comparison c = compare(map, dense);
      ASSERT_EQ(c.knowledge_mismatches, 0u) << "resolution " << res << " scan " << i;
      ASSERT_LE(c.max_rel_error, 1e-4) << "resolution " << res << " scan " << i << " cell ("
                                       << c.worst_x << ", " << c.worst_y << ")";
    }
  }
}

TEST(ScanClassifier, RefusedScansAgreeWithTheReference) {
  wavog::MapParams p;
  ScanClassifier cls;
  ReferenceClassifier ref;
  const float ranges[3] = {1.0f, std::nanf(""), 2.0f};
  const float invalid[2] = {std::nanf(""), -1.0f};
  const wavog::ScanView good{ranges, 3, 0.0, 0.1, 0.1, 5.0};
  wavog::ScanView zero_inc = good;
  zero_inc.angle_increment = 0.0;
  const wavog::ScanView none_valid{invalid, 2, 0.0, 0.1, 0.1, 5.0};
  const wavog::ScanView empty{ranges, 0, 0.0, 0.1, 0.1, 5.0};
  wavog::IntegrateStats st;
  EXPECT_EQ(cls.prepare(p, {0, 0, 0}, good, &st), wavog::ScanStatus::kOk);
  EXPECT_EQ(cls.prepare(p, {0, 0, 0}, zero_inc, &st), wavog::ScanStatus::kBadGeometry);
  EXPECT_EQ(cls.prepare(p, {0, 0, 0}, none_valid, &st), wavog::ScanStatus::kNoValidBeam);
  EXPECT_EQ(cls.prepare(p, {0, 0, 0}, empty, &st), wavog::ScanStatus::kEmpty);
  EXPECT_EQ(cls.prepare(p, {std::nan(""), 0, 0}, good, &st), wavog::ScanStatus::kBadPose);
  EXPECT_TRUE(ref.prepare(p, {0, 0, 0}, good));
  EXPECT_FALSE(ref.prepare(p, {0, 0, 0}, zero_inc));
  EXPECT_FALSE(ref.prepare(p, {0, 0, 0}, none_valid));
}

// The pseudo-bearing table alone: every sector it gives is the reference's lround of the bearing
// (n for outside the fan), also a hair beside a boundary and across the seam of a whole turn;
// and it leaves few directions unsure.
TEST(SectorTable, SureBucketsGiveTheReferenceBeam) {
  struct Geometry {
    int n;
    double amin, inc;
  };
  const double pi = 3.14159265358979323846;
  const Geometry geometries[] = {{361, -pi / 2, pi / 360},         // LMS-291, 180 deg
                                 {360, -pi / 2, pi / 360},         // fr079
                                 {1081, -2.35619449, 0.00436332},  // 270 deg
                                 {720, -pi, 2 * pi / 720},         // a whole turn
                                 {720, -pi, 2 * pi / 720 + 1e-9},  // slightly more than a turn
                                 {16, 1.0, 0.2},                   // coarse
                                 {5, 7.5, 0.01}};                  // angle_min beyond 2 pi
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-pi, pi), unit(0.0, 1.0);
  for (const Geometry& g : geometries) {
    wavog::detail::SectorTable table;
    table.prepare(g.n, g.amin, g.inc);
    const double seam = 0.5 * (g.amin + g.amin + g.inc * (g.n - 1)) - pi;
    const auto reference = [&](double dx, double dy) {
      double beta = std::atan2(dy, dx);
      beta -= 2 * pi * std::floor((beta - seam) / (2 * pi));
      const long j = std::lround((beta - g.amin) / g.inc);
      return j < 0 || j >= g.n ? g.n : static_cast<int>(j);
    };
    std::size_t sure = 0, count = 0;
    for (int i = 0; i < 200000; ++i) {
      double a;
      if (i % 2 == 0) {
        a = angle(rng);
      } else {  // a hair from a boundary: 1e-12 .. 1e-6 rad either side
        const int k = static_cast<int>(unit(rng) * (g.n + 1));
        const double off = std::pow(10.0, -12.0 + 6.0 * unit(rng)) * (unit(rng) < 0.5 ? -1 : 1);
        a = g.amin + (k - 0.5) * g.inc + off;
      }
      const double r = 0.01 + 100.0 * unit(rng);
      const double dx = r * std::cos(a), dy = r * std::sin(a);
      const std::int32_t got = table.sector(dx, dy);
      count += i % 2 == 0 ? 1 : 0;
      if (got == wavog::detail::SectorTable::kUnsure) continue;
      sure += i % 2 == 0 ? 1 : 0;
      ASSERT_EQ(got, reference(dx, dy)) << "n " << g.n << " inc " << g.inc << " angle " << a;
    }
    // Of the directions drawn anywhere, at most a sixth are unsure (near a boundary).
    EXPECT_GT(static_cast<double>(sure), 0.83 * static_cast<double>(count)) << "n " << g.n;
  }
}

// The endpoints of hit beams come from unit vectors rotated by the pose, a few ulps from the
// reference's cos / sin of theta + bearing: an endpoint that lands on a cell edge must still get
// the reference's cell. Poses are placed so that the reference's endpoint is within ulps of an
// edge, where the rotated arithmetic alone picks the other cell now and then (counted).
TEST(PreparedScan, HitCellsAreTheReferencesAtCellEdges) {
  wavog::MapParams params = wavog::MapParams::defaultsFor(wavog::PolicyType::kClamp);
  params.grid.resolution = 0.0625;  // a power of two: ex / res is exact
  const double res = params.grid.resolution;
  std::mt19937 rng(34);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::size_t differ = 0, checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double theta = -3.0 + 6.0 * unit(rng), amin = -1.5 + 3.0 * unit(rng);
    const float range = static_cast<float>(1.0 + 30.0 * unit(rng));
    const double z = range;
    const double bearing = theta + (amin + 0.0 * 0.01);
    const double ref_c = std::cos(bearing);
    const double rot_c = std::cos(theta) * std::cos(amin) - std::sin(theta) * std::sin(amin);
    const double k = std::floor(100.0 * unit(rng));
    double px = k * res - z * ref_c;
    for (int step = 0; step < 8; ++step, px = std::nextafter(px, 1e9)) {
      const double ref_x = std::floor((px + z * ref_c) / res);
      if (ref_x == std::floor((px + z * rot_c) / res)) continue;
      ++differ;
      wavog::ScanView view;
      view.ranges = &range;
      view.count = 1;
      view.angle_min = amin;
      view.angle_increment = 0.01;
      view.range_min = 0.0;
      view.range_max = 100.0;
      wavog::detail::PreparedScan ps;
      wavog::IntegrateStats st;
      ASSERT_EQ(ps.prepare(params, wavog::Pose2{px, 0.3, theta}, view, &st),
                wavog::ScanStatus::kOk);
      EXPECT_EQ(ps.hit_x[0], static_cast<std::int64_t>(ref_x)) << "trial " << trial;
      ++checked;
    }
  }
  EXPECT_GT(differ, 10u);  // the rotated arithmetic alone would have missed these cells
  EXPECT_EQ(checked, differ);
}

}  // namespace
}  // namespace wavog_test

// The SSE2 quotient of a 4 x 4 group's buckets is the scalar expression, bit for bit, including
// quotients just below and above an integer and the table mask's wrap.
TEST(ScanNumerics, QuotientBucketsAreTheScalarQuotient) {
  std::mt19937 rng(3401u);
  std::uniform_real_distribution<double> term(-3.0, 3.0), den(0.5, 4.0);
  const std::uint32_t mask = 1023u;
  for (int trial = 0; trial < 2000; ++trial) {
    std::array<double, 4> nc, nr, dc, dr;
    for (std::size_t i = 0; i < 4; ++i) {
      dc[i] = den(rng);
      dr[i] = den(rng);
      nc[i] = 256.0 * (dc[i] + term(rng));
      nr[i] = 256.0 * dr[i];
    }
    if (trial % 7 == 0) nc[1] = 300.0 * (dc[1] + dr[2]) - nr[2];  // an exact integer quotient
    std::array<std::uint32_t, 16> got{};
    wavog::detail::quotientBuckets16(nc.data(), nr.data(), dc.data(), dr.data(), mask, got.data());
    for (std::size_t i = 0; i < 16; ++i) {
      const double v = (nc[i & 3] + nr[i >> 2]) / (dc[i & 3] + dr[i >> 2]);
      ASSERT_EQ(got[i], static_cast<std::uint32_t>(static_cast<std::int32_t>(v)) & mask)
          << "trial " << trial << " cell " << i << " quotient " << v;
    }
  }
}

// A tile's crossings (SSE2 where built with it) follow their rule cell by cell: cell p of line l
// is below when p < c - margin and above when p > c + margin, c = q0 + l step, never wrongly, and
// exactly unless p lies within 1e-12 of c -+ margin (where rounding may leave it on neither side,
// to the per-cell path); including crossings just off an integer, beyond either end, wide margins.
TEST(ScanNumerics, TileCrossingsAreTheirRule) {
  std::mt19937 rng(4301u);
  std::uniform_real_distribution<double> q(-12.0, 20.0), step(-2.0, 2.0), margin(0.0, 0.7);
  std::size_t unsure = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    double q0 = q(rng);
    const double st = trial % 5 == 0 ? 0.0 : step(rng);
    const double m = trial % 3 == 0 ? 1e-9 : margin(rng);
    if (trial % 7 == 0) q0 = std::round(q0) + (trial % 2 == 0 ? 1e-12 : -1e-12);
    const wavog::detail::tile::Crossings x = wavog::detail::tile::crossings(q0, st, m);
    ASSERT_EQ(x.low & x.high, 0u) << "trial " << trial;
    for (unsigned l = 0; l < 8; ++l) {
      const double c = q0 + static_cast<double>(l) * st;
      for (unsigned p = 0; p < 8; ++p) {
        const unsigned bit = p + 8 * l;
        const double pos = static_cast<double>(p);
        const bool low = (x.low >> bit) & 1u, high = (x.high >> bit) & 1u;
        if (low) {
          ASSERT_LT(pos, c - m) << "trial " << trial;
        }
        if (high) {
          ASSERT_GT(pos, c + m) << "trial " << trial;
        }
        if (std::fabs(pos - (c - m)) > 1e-12) {
          ASSERT_EQ(low, pos < c - m) << "trial " << trial;
        }
        if (std::fabs(pos - (c + m)) > 1e-12) {
          ASSERT_EQ(high, pos > c + m) << "trial " << trial;
        }
        unsure += ((x.low | x.high) >> bit) & 1u ? 0 : 1;
      }
    }
  }
  EXPECT_GT(unsure, 0u);  // wide margins leave cells on neither side
  // A boundary parallel to the lines (a zero component: step and margin infinite, line 0's
  // crossing 0 x inf = NaN) leaves every cell of a NaN line on neither side.
  const double inf = std::numeric_limits<double>::infinity();
  for (double q0 : {-inf, inf, std::nan("")}) {
    const wavog::detail::tile::Crossings x = wavog::detail::tile::crossings(q0, inf, inf);
    EXPECT_EQ(x.low | x.high, 0u) << q0;
  }
  const wavog::detail::tile::Crossings nan_line =
      wavog::detail::tile::crossings(3.5, std::nan(""), 1e-9);
  EXPECT_EQ(nan_line.low | nan_line.high, 0u);
}

TEST(ScanNumerics, TileTransposeSwapsRowsAndColumns) {
  std::mt19937_64 rng(17u);
  for (int trial = 0; trial < 1000; ++trial) {
    const std::uint64_t m = rng();
    const std::uint64_t t = wavog::detail::tile::transpose(m);
    for (unsigned x = 0; x < 8; ++x) {
      for (unsigned y = 0; y < 8; ++y) {
        ASSERT_EQ((t >> (y + 8 * x)) & 1u, (m >> (x + 8 * y)) & 1u);
      }
    }
  }
}
