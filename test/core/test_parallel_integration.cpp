// Parallel integration over blocks (MapParams::num_threads): the map, the per-scan figures and
// the saved file are the same, byte for byte, for 1, 2 and 4 threads, for every policy and prior,
// on random scans (with region clearing in between) and on the first 500 fr079 scans; the scan's
// preparation, shared with the workers, is the same field for field. Also the make tsan target's
// core test of the parallel path.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "classify/prepared_scan.h"
#include "test_support.h"
#include "update/worker_pool.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace wavog_test {
namespace {

using wavog::IntegrateStats;
using wavog::MapParams;
using wavog::MapStats;
using wavog::WaveletMap;

constexpr int kThreadCounts[] = {1, 2, 4};

std::vector<char> savedBytes(const WaveletMap& map, const std::string& name) {
  // Per process: the same test run beside it (another build, a sanitizer run) writes its own.
  const std::string path =
      ::testing::TempDir() + "wavog_parallel_" + std::to_string(::getpid()) + "_" + name + ".wavog";
  map.save(path);
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::remove(path.c_str());
  return bytes;
}

void expectSameScan(const IntegrateStats& a, const IntegrateStats& b, const std::string& what) {
  EXPECT_EQ(a.status, b.status) << what;
  EXPECT_EQ(a.beams_hit, b.beams_hit) << what;
  EXPECT_EQ(a.beams_no_return, b.beams_no_return) << what;
  EXPECT_EQ(a.beams_invalid, b.beams_invalid) << what;
  EXPECT_EQ(a.nodes_visited, b.nodes_visited) << what;
  EXPECT_EQ(a.blocks_touched, b.blocks_touched) << what;
  EXPECT_EQ(a.touched.min_x, b.touched.min_x) << what;
  EXPECT_EQ(a.touched.min_y, b.touched.min_y) << what;
  EXPECT_EQ(a.touched.max_x, b.touched.max_x) << what;
  EXPECT_EQ(a.touched.max_y, b.touched.max_y) << what;
}

void expectSameStats(const MapStats& a, const MapStats& b, const std::string& what) {
  EXPECT_EQ(a.blocks, b.blocks) << what;
  EXPECT_EQ(a.nodes, b.nodes) << what;
  EXPECT_EQ(a.bytes, b.bytes) << what;
  EXPECT_EQ(a.bytes_reserved, b.bytes_reserved) << what;
  EXPECT_EQ(a.nodes_visited_last, b.nodes_visited_last) << what;
  EXPECT_EQ(a.observed_cells, b.observed_cells) << what;
}

// One map per thread count, fed the same scans; compared scan by scan and at the end.
class ThreadRun {
 public:
  explicit ThreadRun(const MapParams& p) {
    for (int t : kThreadCounts) {
      MapParams q = p;
      q.num_threads = t;
      maps_.push_back(std::make_unique<WaveletMap>(q));
    }
  }
  // Returns the blocks the scan touched.
  std::uint32_t integrate(const OwnedScan& s, const std::string& what) {
    const IntegrateStats first = maps_[0]->integrate(s.pose, s.view());
    for (std::size_t i = 1; i < maps_.size(); ++i) {
      const std::string w = what + ", " + std::to_string(kThreadCounts[i]) + " threads";
      expectSameScan(first, maps_[i]->integrate(s.pose, s.view()), w);
      expectSameStats(maps_[0]->stats(), maps_[i]->stats(), w);
    }
    return first.blocks_touched;
  }
  const WaveletMap& first() const { return *maps_[0]; }
  void clearBox(double x0, double y0, double x1, double y1) {
    for (auto& m : maps_) m->clearBox(x0, y0, x1, y1);
  }
  void expectSame(const std::string& what) {
    const std::vector<char> first = savedBytes(*maps_[0], what + "_1");
    ASSERT_GT(first.size(), 100u) << what;
    for (std::size_t i = 1; i < maps_.size(); ++i) {
      const std::string w = what + ", " + std::to_string(kThreadCounts[i]) + " threads";
      expectSameStats(maps_[0]->stats(true), maps_[i]->stats(true), w);
      EXPECT_TRUE(first == savedBytes(*maps_[i], what + "_" + std::to_string(i)))
          << w << ": saved files differ";
    }
  }

 private:
  std::vector<std::unique_ptr<WaveletMap>> maps_;
};

// Every policy and prior, forgetting eager and pruned, and the payloads: reflection layers and
// normal-distribution cells (saved in the file) and forgetting in seconds.
std::vector<NamedParams> configurations(double res, int block_levels) {
  return everyPolicyWithVariants(res, block_levels, {"forget", "none", "max"});
}

TEST(ParallelIntegration, RandomScansGiveTheSameMapForOneTwoAndFourThreads) {
  for (const auto& np : configurations(0.1, 4)) {
    ThreadRun run(np.params);
    RandomScans scans(11, 40.0);
    std::uint64_t blocks = 0;
    for (int i = 0; i < 60; ++i) {
      blocks += run.integrate(scans.next(), np.name + ", scan " + std::to_string(i));
      // Clearing frees nodes (to the pool's own list and to blocks' spares) and erases blocks.
      if (i == 20) run.clearBox(-8.0, -6.0, 5.0, 9.0);
      if (i == 40) run.clearBox(-30.0, -30.0, 0.0, 30.0);
    }
    EXPECT_GT(blocks, 60u * 4) << np.name << ": too few blocks per scan to share between threads";
    run.expectSame(np.name);
  }
}

// A scan of at most 8 blocks is split below their roots (src/core/update/split_plan.h), and
// threads share the parts of one block: one, two and four threads still give the same map, and
// it is, cell for cell, the map of the walk of whole blocks (a map with NDT cells is not split,
// and they do not change its occupancy). Blocks of 8 levels split 3 levels down, of 5 levels 2.
TEST(ParallelIntegration, ScansOfFewBlocksAreSplitAndGiveTheSameMap) {
  struct Case {
    int levels;
    double half_extent;  // m: scans within +-half / 2, ranges below 0.45 half
  };
  for (const Case c : {Case{8, 20.0}, Case{5, 3.0}}) {
    auto configs = everyPolicy(0.1, c.levels);
    NamedParams eager = configs[5];
    ASSERT_EQ(eager.name, "forget");
    eager.name = "forget_eager";
    eager.params.lazy_forgetting = false;
    configs.push_back(eager);
    for (const auto& np : configs) {
      const std::string what = np.name + ", " + std::to_string(c.levels) + " levels";
      ThreadRun run(np.params);
      MapParams whole_params = np.params;
      whole_params.ndt = true;
      WaveletMap whole(whole_params);
      RandomScans scans(5, c.half_extent);
      for (int i = 0; i < 50; ++i) {
        const OwnedScan s = scans.next();
        const std::uint32_t blocks = run.integrate(s, what + ", scan " + std::to_string(i));
        EXPECT_LE(blocks, 8u) << what << ": the scan is not split";
        whole.integrate(s.pose, s.view());
        if (i == 25) {  // clearing frees nodes to the blocks' spares, which the parts then take
          const double h = 0.25 * c.half_extent;
          run.clearBox(-h, -h, h, 0.5 * h);
          whole.clearBox(-h, -h, h, 0.5 * h);
        }
      }
      run.expectSame(what);
      EXPECT_EQ(run.first().stats().nodes, whole.stats().nodes) << what;
      expectSameCells(run.first(), whole, static_cast<int>(c.half_extent / 0.1), 0.0);
    }
  }
}

TEST(ParallelIntegration, RealDataFr079First500ScansGiveTheSameMapForOneTwoAndFourThreads) {
  const std::string dir = dataDir();
  ASSERT_FALSE(dir.empty());
  const auto log = wavog::readCarmenLog(dir + "/fr079-corrected.log.gz", 500);
  ASSERT_EQ(log.size(), 500u);
  for (const auto& np : configurations(0.05, 6)) {
    ThreadRun run(np.params);
    for (std::size_t i = 0; i < log.size(); ++i) {
      OwnedScan o;
      o.pose = log[i].laser_pose;
      const auto v = log[i].view();
      o.ranges.assign(v.ranges, v.ranges + v.count);
      o.angle_min = v.angle_min;
      o.angle_increment = v.angle_increment;
      o.range_min = v.range_min;
      o.range_max = v.range_max;
      run.integrate(o, np.name + ", fr079 scan " + std::to_string(i));
    }
    run.expectSame("fr079_" + np.name);
  }
}

// Every field the classifier reads, and the beam counts, of scans prepared on the calling thread
// alone and with the help of 1 and 3 workers (pieces of 64 beams and the two tables, shared):
// random scans (up to 3 pieces, every kind of reading), long ones (17 pieces) and refused ones,
// with and without no-return clearing, a wide band and the reference's endpoints (NDT).
TEST(ParallelIntegration, PreparedScanIsTheSameWithAndWithoutHelpers) {
  using wavog::detail::PreparedScan;
  wavog::detail::WorkerPool two(2), four(4);
  for (int variant = 0; variant < 4; ++variant) {
    MapParams p;
    p.grid.resolution = 0.05;
    p.sensor.no_return_clear = variant % 2 == 1 ? 6.0 : 0.0;
    p.sensor.band_width = variant == 2 ? 0.3 : 0.0;
    p.ndt = variant == 3;
    RandomScans scans(17 + static_cast<std::uint32_t>(variant), 30.0);
    for (int i = 0; i < 120; ++i) {
      OwnedScan s = scans.next();
      if (i % 4 == 3) {  // a long scan: the ranges repeated, over the same field of view
        const double fov = s.angle_increment * static_cast<double>(s.ranges.size());
        const std::vector<float> r = s.ranges;
        s.ranges.clear();
        while (s.ranges.size() < 1081) s.ranges.insert(s.ranges.end(), r.begin(), r.end());
        s.ranges.resize(1081);
        s.angle_increment = fov / 1081.0;
      }
      if (i == 50) s.ranges.assign(s.ranges.size(), std::numeric_limits<float>::quiet_NaN());
      const std::string what = "variant " + std::to_string(variant) + ", scan " + std::to_string(i);
      PreparedScan alone;
      IntegrateStats st_alone;
      wavog::ScanStatus status;
      {
        const wavog::detail::PrepareHelpers none(nullptr);
        status = alone.prepare(p, s.pose, s.view(), &st_alone);
      }
      EXPECT_EQ(status == wavog::ScanStatus::kNoValidBeam, i == 50) << what;
      if (status == wavog::ScanStatus::kOk) {
        // The hit keys (merged from the pieces' sorted runs) and the invalid beams' prefix, as
        // one thread computes them from the beams.
        std::vector<std::uint64_t> keys;
        std::vector<int> prefix{0};
        for (std::size_t j = 0; j < alone.kind.size(); ++j) {
          if (alone.kind[j] == wavog::detail::BeamKind::kHit) {
            keys.push_back(PreparedScan::cellKey(alone.hit_x[j], alone.hit_y[j]));
          }
          prefix.push_back(prefix.back() + (alone.kind[j] == wavog::detail::BeamKind::kInvalid));
        }
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
        EXPECT_TRUE(alone.hits == keys) << what;
        EXPECT_TRUE(alone.invalid_prefix == prefix) << what;
      }
      for (wavog::detail::WorkerPool* pool : {&two, &four}) {
        PreparedScan shared;
        IntegrateStats st_shared;
        {
          const wavog::detail::PrepareHelpers helpers(pool);
          ASSERT_EQ(shared.prepare(p, s.pose, s.view(), &st_shared), status) << what;
        }
        const std::string w = what + ", " + std::to_string(pool->threads()) + " threads";
        EXPECT_EQ(st_alone.beams_hit, st_shared.beams_hit) << w;
        EXPECT_EQ(st_alone.beams_no_return, st_shared.beams_no_return) << w;
        EXPECT_EQ(st_alone.beams_invalid, st_shared.beams_invalid) << w;
        EXPECT_EQ(st_alone.beams_beyond_limit, st_shared.beams_beyond_limit) << w;
        if (status != wavog::ScanStatus::kOk) continue;
        EXPECT_EQ(alone.reach, shared.reach) << w;
        EXPECT_TRUE(alone.kind == shared.kind) << w;
        EXPECT_TRUE(alone.hits == shared.hits) << w;
        EXPECT_TRUE(alone.invalid_prefix == shared.invalid_prefix) << w;
        EXPECT_TRUE(alone.min_e2 == shared.min_e2) << w;
        EXPECT_TRUE(alone.max_u2 == shared.max_u2) << w;
        EXPECT_TRUE(alone.bnd_x == shared.bnd_x && alone.bnd_y == shared.bnd_y) << w;
        EXPECT_TRUE(alone.hit_x == shared.hit_x && alone.hit_y == shared.hit_y) << w;
        EXPECT_TRUE(alone.hit_group == shared.hit_group && alone.hit_bit == shared.hit_bit) << w;
        ASSERT_EQ(alone.leaf.size(), shared.leaf.size()) << w;
        for (std::size_t j = 0; j < alone.leaf.size(); ++j) {
          EXPECT_EQ(alone.leaf[j].e, shared.leaf[j].e) << w << ", beam " << j;
          EXPECT_EQ(alone.leaf[j].o, shared.leaf[j].o) << w << ", beam " << j;
          if (j < alone.kind.size() && alone.kind[j] == wavog::detail::BeamKind::kHit) {
            EXPECT_EQ(alone.end_x[j], shared.end_x[j]) << w << ", beam " << j;
            EXPECT_EQ(alone.end_y[j], shared.end_y[j]) << w << ", beam " << j;
          }
        }
      }
    }
  }
}

TEST(ParallelIntegration, ThreadCountOutsideItsRangeIsRejected) {
  MapParams p;
  p.num_threads = -1;
  EXPECT_THROW(WaveletMap{p}, std::invalid_argument);
  p.num_threads = 257;
  EXPECT_THROW(WaveletMap{p}, std::invalid_argument);
  p.num_threads = 0;  // one per core
  EXPECT_NO_THROW(WaveletMap{p});
}

}  // namespace
}  // namespace wavog_test
