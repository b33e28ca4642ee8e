// The slow dense reference: a plain grid over a fixed window of finest cells that classifies every
// cell independently against each scan (same E/O/U sector model and REP 117 rules as the core,
// written again here cell by cell) and applies the policy cell by cell, in double precision.
#ifndef WAVOG_MAPPING_TEST_CORE_DENSE_REFERENCE_H_
#define WAVOG_MAPPING_TEST_CORE_DENSE_REFERENCE_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_test {

/// The reference's sector model of one scan, cell by cell: std::atan2 bearing, lround to a beam,
/// sqrt distance against the beam's limits, a hit endpoint in the cell wins (no shortcuts).
class ReferenceClassifier {
 public:
  /// False when the core would refuse the scan or it has no valid beam (nothing is classified).
  bool prepare(const wavog::MapParams& p, const wavog::Pose2& pose, const wavog::ScanView& scan);
  /// E, O or U of finest cell (ix, iy).
  wavog::CellClass cellClass(std::int64_t ix, std::int64_t iy) const;
  /// The map-frame end-points of the hit beams, in ascending bearing order.
  std::vector<std::pair<double, double>> endpoints(const wavog::Pose2& pose,
                                                   const wavog::ScanView& scan) const;
  /// Largest band end of the valid beams (m): every cell beyond is U.
  double reach() const { return reach_; }

 private:
  wavog::Pose2 pose_;
  int n_ = 0;
  double amin_ = 0, inc_ = 0, seam_ = 0, res_ = 0, reach_ = 0;
  std::vector<int> kind_;  // 0 invalid, 1 hit, 2 clearing no-return
  std::vector<double> ze_, zu_;
  std::set<std::pair<std::int64_t, std::int64_t>> hits_;
};

class DenseReference {
 public:
  /// `extent`: the finest cells modelled; cells outside it are not tracked.
  DenseReference(const wavog::MapParams& params, const wavog::CellBox& extent);
  /// Several layers, one per parameter set, sharing the classification of each scan (all sets
  /// must share grid and sensor geometry: resolution, band_width, max_range, no_return_clear).
  DenseReference(const std::vector<wavog::MapParams>& layers, const wavog::CellBox& extent);

  /// Integrates the scan `repeat` times (classified once; NDT cells: repeat must be 1).
  void integrate(const wavog::Pose2& pose, const wavog::ScanView& scan, std::size_t repeat = 1);
  /// Sets the forgetting rate of layer `layer` for the following scans (a per-scan gamma, as
  /// forget_half_life makes them).
  void setGamma(std::size_t layer, double gamma) { layers_.at(layer).policy.gamma = gamma; }

  /// Sets every cell of layer `layer` to `value` (a prior of its own).
  void setInitial(std::size_t layer, double value) {
    std::fill(v_.at(layer).begin(), v_.at(layer).end(), value);
  }
  /// The clamps' counts of hits (layer 0) and misses (layer 1): after each update of a cell their
  /// sum is bounded at `bound`, scaling both down, and where the cell has hits and layer
  /// `occupancy` (if any) is then within 1e-5 of `empty_bound` they become 0 and `bound`.
  void boundCounts(double bound, std::size_t occupancy = SIZE_MAX,
                   double empty_bound = -std::numeric_limits<double>::infinity()) {
    sum_bound_ = bound;
    occupancy_layer_ = occupancy;
    empty_bound_ = empty_bound;
  }
  /// Replaces the parameters of layer `layer` (same geometry) for the following scans.
  void setLayerParams(std::size_t layer, const wavog::MapParams& p) { layers_.at(layer) = p; }
  /// Every cell unobserved again (values kept).
  void forgetKnowledge() { std::fill(known_.begin(), known_.end(), 0); }

  /// Selects the layer that value(), known() and the block functions read (default 0).
  void selectLayer(std::size_t layer) { layer_ = layer; }
  double value(std::int64_t ix, std::int64_t iy) const { return v_[layer_][index(ix, iy)]; }
  bool known(std::int64_t ix, std::int64_t iy) const { return known_[index(ix, iy)] != 0; }
  const wavog::CellBox& extent() const { return extent_; }

  /// Mean of the 2^s x 2^s block at scale-s index (bx, by) (all cells, unobserved at the prior),
  /// max over its observed cells (-inf if none), and whether any is observed.
  double blockMean(int s, std::int64_t bx, std::int64_t by) const;
  double blockMaxObserved(int s, std::int64_t bx, std::int64_t by) const;
  bool blockAnyKnown(int s, std::int64_t bx, std::int64_t by) const;

  /// MapParams::ndt of layer 0: the Gaussian of finest cell (ix, iy), false when it holds none.
  bool ndtCell(std::int64_t ix, std::int64_t iy, wavog::NdtCell* out) const;
  /// The Gaussians of the scale-s cells in `window` (scale-s units), sorted by (iy, ix), merged
  /// from the map-frame moment sums of their finest cells.
  std::vector<wavog::NdtCell> ndtLayer(int s, const wavog::CellBox& window) const;
  std::size_t ndtCells() const { return ndt_.size(); }

  /// Cells changed by the last scan (for tests of the update footprint).
  std::size_t lastUpdatedCells() const { return last_updated_; }

 private:
  std::size_t index(std::int64_t ix, std::int64_t iy) const;
  static double apply(const wavog::MapParams& p, bool occupied, double x);
  void integrateNdt(const ReferenceClassifier& ref, const wavog::Pose2& pose,
                    const wavog::ScanView& scan);

  std::vector<wavog::MapParams> layers_;
  wavog::MapParams p_;  // geometry shared by the layers
  wavog::CellBox extent_;
  std::size_t layer_ = 0;
  std::vector<std::vector<double>> v_;
  std::vector<std::uint8_t> known_;
  /// Map-frame moment sums of the end-points of each cell holding a Gaussian:
  /// w, sum w x, sum w y, sum w x^2, sum w x y, sum w y^2.
  struct Moments {
    double w = 0, x = 0, y = 0, xx = 0, xy = 0, yy = 0;
  };
  std::map<std::pair<std::int64_t, std::int64_t>, Moments> ndt_;  // keyed (iy, ix)
  static wavog::NdtCell gaussian(const Moments& m);
  std::size_t last_updated_ = 0;
  double sum_bound_ = std::numeric_limits<double>::infinity();
  std::size_t occupancy_layer_ = SIZE_MAX;
  double empty_bound_ = -std::numeric_limits<double>::infinity();
};

}  // namespace wavog_test

#endif  // WAVOG_MAPPING_TEST_CORE_DENSE_REFERENCE_H_
