// The structures wavog_compare runs side by side, behind one small interface (one virtual call per
// scan, not per beam): wavog_core's map (any policy), OctoMap as octomap_server uses it, and the
// dense baseline grid. Each integrates scans, reports its own memory and observed cells, and
// classifies the cells of a box for the agreement figures. Private to wavog_compare.
#ifndef WAVOG_MAPPING_TOOLS_COMPARE_SUBJECTS_H_
#define WAVOG_MAPPING_TOOLS_COMPARE_SUBJECTS_H_

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "compare/workloads.h"
#include "wavog_mapping/baseline/dense_grid.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_compare {

/// Per-cell class for agreement: unobserved, free (p < 0.5), occupied (p > 0.5), undecided.
enum Cls : std::uint8_t { kUnobs = 0, kFree = 1, kOcc = 2, kHalf = 3 };

inline Cls classOf(double log_odds) {
  if (log_odds > 0.0) return kOcc;
  if (log_odds < 0.0) return kFree;
  return kHalf;
}

class Subject {
 public:
  virtual ~Subject() = default;
  virtual void integrate(const Scan& scan) = 0;
  /// Bytes by the structure's own account.
  virtual std::size_t ownBytes() const = 0;
  /// Observed finest cells by the structure's own account.
  virtual std::uint64_t observedCells() const = 0;
  /// Class of every cell of `box` (row-major, x fastest).
  virtual std::vector<std::uint8_t> classify(const wavog::CellBox& box) const = 0;
  /// Work done so far by the structure's own count (nodes visited, cells updated); 0 if unknown.
  std::uint64_t work() const { return work_; }

 protected:
  std::uint64_t work_ = 0;
};

class WavogSubject : public Subject {
 public:
  explicit WavogSubject(const wavog::MapParams& params) : map_(params) {}
  void integrate(const Scan& scan) override {
    work_ += map_.integrate(scan.pose, scan.view()).nodes_visited;
  }
  std::size_t ownBytes() const override { return map_.stats().bytes; }
  std::uint64_t observedCells() const override { return map_.stats(true).observed_cells; }
  std::vector<std::uint8_t> classify(const wavog::CellBox& box) const override {
    const wavog::Raster r = map_.exportScale(0, box, wavog::Aggregation::kMean);
    std::vector<std::uint8_t> out(r.log_odds.size(), kUnobs);
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (r.known[i] != 0) out[i] = classOf(r.log_odds[i]);
    }
    return out;
  }

 private:
  wavog::WaveletMap map_;
};

/// OctoMap as octomap_server uses it: one insertPointCloud per scan of the beam end points at
/// z = 0, sensor origin, maxrange = the no-return clearing distance (no-return beams are put beyond
/// it, so OctoMap clears free space up to maxrange and marks no hit).
class OctoMapSubject : public Subject {
 public:
  OctoMapSubject(double resolution, double no_return_clear)
      : tree_(resolution), clear_(no_return_clear) {
    tree_.setProbHit(0.7);
    tree_.setProbMiss(0.4);
    tree_.setClampingThresMin(0.12);
    tree_.setClampingThresMax(0.97);
  }
  void integrate(const Scan& scan) override {
    cloud_.clear();
    cloud_.reserve(scan.ranges.size());
    const double c = std::cos(scan.pose.theta);
    const double s = std::sin(scan.pose.theta);
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const double r = static_cast<double>(scan.ranges[i]);
      if (std::isnan(r) || r <= 0.0 || r < scan.range_min) continue;  // REP 117: invalid
      double length = r;
      if (r >= scan.range_max) {  // no return (+inf included)
        if (!(clear_ > 0.0)) continue;
        length = clear_ + 1.0;  // beyond maxrange: OctoMap clears up to maxrange, no hit
      }
      const double a = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
      const double ca = std::cos(a);
      const double sa = std::sin(a);
      cloud_.push_back(static_cast<float>(scan.pose.x + length * (c * ca - s * sa)),
                       static_cast<float>(scan.pose.y + length * (s * ca + c * sa)), 0.0f);
    }
    const octomap::point3d origin(static_cast<float>(scan.pose.x), static_cast<float>(scan.pose.y),
                                  0.0f);
    tree_.insertPointCloud(cloud_, origin, clear_ > 0.0 ? clear_ : -1.0, false, false);
  }
  std::size_t ownBytes() const override { return tree_.memoryUsage(); }
  std::uint64_t observedCells() const override {
    std::uint64_t cells = 0;
    forEachLeafInLayer([&cells](std::int64_t, std::int64_t, std::int64_t n, double) {
      cells += static_cast<std::uint64_t>(n * n);
    });
    return cells;
  }
  std::vector<std::uint8_t> classify(const wavog::CellBox& box) const override {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(box.width() * box.height()), kUnobs);
    forEachLeafInLayer([&](std::int64_t x0, std::int64_t y0, std::int64_t n, double lo) {
      for (std::int64_t y = std::max(y0, box.min_y); y < std::min(y0 + n, box.max_y); ++y) {
        for (std::int64_t x = std::max(x0, box.min_x); x < std::min(x0 + n, box.max_x); ++x) {
          out[static_cast<std::size_t>((y - box.min_y) * box.width() + (x - box.min_x))] =
              classOf(lo);
        }
      }
    });
    return out;
  }

 private:
  /// Calls f(min cell x, min cell y, cells per side, log-odds) for every leaf covering the z = 0
  /// layer (key 2^15 along z). The scans never leave that layer, so leaves are single cells unless
  /// OctoMap pruned them.
  template <typename F>
  void forEachLeafInLayer(F f) const {
    const unsigned max_depth = tree_.getTreeDepth();
    const std::int64_t half = std::int64_t{1} << (max_depth - 1);  // key of coordinate 0
    for (auto it = tree_.begin_leafs(), end = tree_.end_leafs(); it != end; ++it) {
      const std::int64_t n = std::int64_t{1} << (max_depth - it.getDepth());
      const octomap::OcTreeKey& key = it.getIndexKey();  // smallest key the leaf covers
      const std::int64_t kz = key[2];
      if (half < kz || half >= kz + n) continue;
      f(static_cast<std::int64_t>(key[0]) - half, static_cast<std::int64_t>(key[1]) - half, n,
        static_cast<double>(it->getLogOdds()));
    }
  }

  octomap::OcTree tree_;
  double clear_;
  octomap::Pointcloud cloud_;
};

class DenseSubject : public Subject {
 public:
  DenseSubject(const wavog::baseline::DenseGridParams& params, const wavog::CellBox& presize)
      : grid_(params) {
    grid_.reserve(presize);
  }
  wavog::CellBox extent() const { return grid_.extent(); }
  void integrate(const Scan& scan) override {
    work_ += grid_.integrate(scan.pose, scan.view()).cells_updated;
  }
  std::size_t ownBytes() const override { return grid_.bytes(); }
  std::uint64_t observedCells() const override { return grid_.countObserved(); }
  std::vector<std::uint8_t> classify(const wavog::CellBox& box) const override {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(box.width() * box.height()), kUnobs);
    std::size_t i = 0;
    for (std::int64_t y = box.min_y; y < box.max_y; ++y) {
      for (std::int64_t x = box.min_x; x < box.max_x; ++x, ++i) {
        const std::int16_t v = grid_.rawValue(x, y);
        if (v != wavog::baseline::DenseGrid::kUnknown) out[i] = classOf(static_cast<double>(v));
      }
    }
    return out;
  }
  /// Bounding box of the observed cells (empty if none).
  wavog::CellBox observedBox() const {
    const wavog::CellBox e = grid_.extent();
    wavog::CellBox b{e.max_x, e.max_y, e.min_x, e.min_y};
    for (std::int64_t y = e.min_y; y < e.max_y; ++y) {
      for (std::int64_t x = e.min_x; x < e.max_x; ++x) {
        if (grid_.rawValue(x, y) == wavog::baseline::DenseGrid::kUnknown) continue;
        b.min_x = std::min(b.min_x, x);
        b.max_x = std::max(b.max_x, x + 1);
        b.min_y = std::min(b.min_y, y);
        b.max_y = std::max(b.max_y, y + 1);
      }
    }
    return b;
  }

 private:
  wavog::baseline::DenseGrid grid_;
};

}  // namespace wavog_compare

#endif  // WAVOG_MAPPING_TOOLS_COMPARE_SUBJECTS_H_
