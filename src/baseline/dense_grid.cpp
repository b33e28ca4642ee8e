// Dense int16 log-odds grid with integer DDA ray casting (see dense_grid.h).
#include "wavog_mapping/baseline/dense_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace wavog {
namespace baseline {
namespace {

/// Sub-cell precision of the integer DDA: points are rounded to 1/2^kSubBits of a cell. Products of
/// a distance and a delta stay below 2^(2 * (kSubBits + log2(cells per ray))), far from 2^63.
constexpr int kSubBits = 12;
constexpr std::int64_t kSubOne = std::int64_t{1} << kSubBits;
/// Largest |log-odds| the int16 fixed point can hold with room for one update on top.
constexpr double kMaxAbsLogOdds = 7.9;
/// Points farther than this from the origin (in cells) are refused, so int64 products cannot
/// overflow and a single bad pose cannot allocate the whole memory.
constexpr double kMaxCellCoordinate = 1 << 22;

enum BeamKind : std::uint8_t { kSkip = 0, kHit = 1, kClear = 2 };

std::int16_t toFixed(double log_odds) {
  return static_cast<std::int16_t>(std::lround(log_odds * DenseGrid::kScale));
}

}  // namespace

std::vector<std::string> DenseGridParams::validate() const {
  std::vector<std::string> errors;
  auto fail = [&errors](const std::string& name, double v, const std::string& rule) {
    std::ostringstream os;
    os << name << " (" << v << ") must be " << rule;
    errors.push_back(os.str());
  };
  if (!(resolution > 0.001 && resolution <= 100.0))
    fail("resolution", resolution, "in (0.001, 100]");
  if (!(hit_log_odds > 0.0 && hit_log_odds <= kMaxAbsLogOdds)) {
    fail("hit_log_odds", hit_log_odds, "in (0, 7.9]");
  }
  if (!(miss_log_odds < 0.0 && miss_log_odds >= -kMaxAbsLogOdds)) {
    fail("miss_log_odds", miss_log_odds, "in [-7.9, 0)");
  }
  if (!(clamp_min_log_odds < 0.0 && clamp_min_log_odds >= -kMaxAbsLogOdds)) {
    fail("clamp_min_log_odds", clamp_min_log_odds, "in [-7.9, 0)");
  }
  if (!(clamp_max_log_odds > 0.0 && clamp_max_log_odds <= kMaxAbsLogOdds)) {
    fail("clamp_max_log_odds", clamp_max_log_odds, "in (0, 7.9]");
  }
  if (!(max_range_m >= 0.0 && std::isfinite(max_range_m))) fail("max_range_m", max_range_m, ">= 0");
  if (!(no_return_clear_m >= 0.0 && std::isfinite(no_return_clear_m))) {
    fail("no_return_clear_m", no_return_clear_m, ">= 0");
  }
  if (grow_margin_cells < 0 || grow_margin_cells > 100000) {
    fail("grow_margin_cells", grow_margin_cells, "in [0, 100000]");
  }
  return errors;
}

DenseGrid::DenseGrid(const DenseGridParams& params) : params_(params) {
  const std::vector<std::string> errors = params.validate();
  if (!errors.empty()) {
    std::string message = "DenseGridParams invalid:";
    for (const std::string& e : errors) message += "\n  " + e;
    throw std::invalid_argument(message);
  }
  inv_resolution_ = 1.0 / params.resolution;
  hit_ = toFixed(params.hit_log_odds);
  miss_ = toFixed(params.miss_log_odds);
  clamp_min_ = toFixed(params.clamp_min_log_odds);
  clamp_max_ = toFixed(params.clamp_max_log_odds);
}

void DenseGrid::cacheDirections(const ScanView& scan) {
  if (dir_cos_.size() == scan.count && cached_angle_min_ == scan.angle_min &&
      cached_angle_increment_ == scan.angle_increment) {
    return;
  }
  dir_cos_.resize(scan.count);
  dir_sin_.resize(scan.count);
  for (std::size_t i = 0; i < scan.count; ++i) {
    const double a = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    dir_cos_[i] = std::cos(a);
    dir_sin_[i] = std::sin(a);
  }
  cached_angle_min_ = scan.angle_min;
  cached_angle_increment_ = scan.angle_increment;
}

DenseIntegrateStats DenseGrid::integrate(const Pose2& sensor_pose, const ScanView& scan) {
  DenseIntegrateStats stats;
  if (scan.count == 0 || scan.ranges == nullptr || !std::isfinite(scan.angle_increment) ||
      scan.angle_increment == 0.0 || !std::isfinite(scan.angle_min) ||
      !std::isfinite(sensor_pose.x) || !std::isfinite(sensor_pose.y) ||
      !std::isfinite(sensor_pose.theta)) {
    stats.rejected = true;
    return stats;
  }
  cacheDirections(scan);

  double max_range = params_.max_range_m > 0.0 ? params_.max_range_m : scan.range_max;
  if (!(max_range > 0.0)) max_range = std::numeric_limits<double>::infinity();
  const double clear = params_.no_return_clear_m;

  // Sensor and end points in (fractional) cell units of the map frame.
  const double c = std::cos(sensor_pose.theta);
  const double s = std::sin(sensor_pose.theta);
  const double ox = sensor_pose.x * inv_resolution_;
  const double oy = sensor_pose.y * inv_resolution_;
  if (std::abs(ox) > kMaxCellCoordinate || std::abs(oy) > kMaxCellCoordinate) {
    stats.rejected = true;
    return stats;
  }
  const std::size_t n = scan.count;
  end_x_.resize(n);
  end_y_.resize(n);
  kind_.resize(n);
  std::vector<double>& fx = end_fx_;
  std::vector<double>& fy = end_fy_;
  fx.resize(n);
  fy.resize(n);
  double min_x = ox, max_x = ox, min_y = oy, max_y = oy;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = static_cast<double>(scan.ranges[i]);
    kind_[i] = kSkip;
    double length = 0.0;
    if (std::isnan(r) || r <= 0.0 || r < scan.range_min) {
      ++stats.beams_invalid;  // NaN, -inf, zero, negative or too short: no information
      continue;
    }
    const bool no_return = r >= max_range;  // +inf included
    if (no_return && !(clear > 0.0)) {
      ++stats.beams_no_return;
      continue;
    }
    length = no_return ? clear : r;
    const double d = length * inv_resolution_;
    fx[i] = ox + d * (c * dir_cos_[i] - s * dir_sin_[i]);
    fy[i] = oy + d * (s * dir_cos_[i] + c * dir_sin_[i]);
    if (!(std::abs(fx[i]) <= kMaxCellCoordinate && std::abs(fy[i]) <= kMaxCellCoordinate)) {
      ++stats.beams_invalid;  // absurd reading: refused rather than allocating a huge grid
      continue;
    }
    if (no_return) {
      ++stats.beams_no_return;
      kind_[i] = kClear;
    } else {
      ++stats.beams_hit;
      kind_[i] = kHit;
    }
    min_x = std::min(min_x, fx[i]);
    max_x = std::max(max_x, fx[i]);
    min_y = std::min(min_y, fy[i]);
    max_y = std::max(max_y, fy[i]);
  }
  growToCover(
      static_cast<std::int64_t>(std::floor(min_x)), static_cast<std::int64_t>(std::floor(min_y)),
      static_cast<std::int64_t>(std::floor(max_x)), static_cast<std::int64_t>(std::floor(max_y)));

  // Fixed-point coordinates relative to the grid origin; all non-negative after growToCover.
  const double sub = static_cast<double>(kSubOne);
  const double base_x = static_cast<double>(origin_x_);
  const double base_y = static_cast<double>(origin_y_);
  const auto fixed = [sub](double v) { return static_cast<std::int64_t>(std::floor(v * sub)); };
  const std::int64_t sx = fixed(ox - base_x);
  const std::int64_t sy = fixed(oy - base_y);
  for (std::size_t i = 0; i < n; ++i) {
    if (kind_[i] == kSkip) continue;
    end_x_[i] = fixed(fx[i] - base_x);
    end_y_[i] = fixed(fy[i] - base_y);
  }

  nextStamp();
  // Pass 1: the end-point cells of returns. Doing them first makes a hit win over any miss of the
  // same scan, and the stamp keeps a cell hit by several beams to one update.
  for (std::size_t i = 0; i < n; ++i) {
    if (kind_[i] != kHit) continue;
    const std::int64_t cx = end_x_[i] >> kSubBits;
    const std::int64_t cy = end_y_[i] >> kSubBits;
    Cell& cell = cells_[static_cast<std::size_t>(cy * width_ + cx)];
    if (cell.stamp == stamp_) continue;
    cell.stamp = stamp_;
    const int v = (cell.value == kUnknown ? 0 : cell.value) + hit_;
    cell.value = static_cast<std::int16_t>(std::min<int>(v, clamp_max_));
    ++stats.cells_updated;
  }
  // Pass 2: free space along every ray, end cell excluded.
  for (std::size_t i = 0; i < n; ++i) {
    if (kind_[i] == kSkip) continue;
    stats.cells_updated += traceFree(sx, sy, end_x_[i], end_y_[i]);
  }
  return stats;
}

std::uint64_t DenseGrid::traceFree(std::int64_t sx, std::int64_t sy, std::int64_t ex,
                                   std::int64_t ey) {
  std::int64_t cx = sx >> kSubBits;
  std::int64_t cy = sy >> kSubBits;
  const std::int64_t ecx = ex >> kSubBits;
  const std::int64_t ecy = ey >> kSubBits;
  std::int64_t steps_x = std::abs(ecx - cx);
  std::int64_t steps_y = std::abs(ecy - cy);
  const std::int64_t dx = ex - sx;
  const std::int64_t dy = ey - sy;
  const std::int64_t adx = std::abs(dx);
  const std::int64_t ady = std::abs(dy);
  const std::int64_t step_x = dx > 0 ? 1 : -1;
  const std::int64_t step_idx_y = dy > 0 ? width_ : -width_;
  // The ray crosses the next vertical cell border at t = dist_x / adx and the next horizontal one
  // at t = dist_y / ady; compare dist_x * ady with dist_y * adx to avoid division. Each crossing
  // moves the next border by one cell, i.e. adds kSubOne * ady (resp. kSubOne * adx).
  std::int64_t t_x = (dx > 0 ? ((cx + 1) << kSubBits) - sx : sx - (cx << kSubBits)) * ady;
  std::int64_t t_y = (dy > 0 ? ((cy + 1) << kSubBits) - sy : sy - (cy << kSubBits)) * adx;
  const std::int64_t dt_x = kSubOne * ady;
  const std::int64_t dt_y = kSubOne * adx;

  std::int64_t idx = cy * width_ + cx;
  std::uint64_t updated = 0;
  // Locals, so that the stores into the cells (int16) cannot make the compiler reload them.
  Cell* const cells = cells_.data();
  const std::uint16_t stamp = stamp_;
  const int miss = miss_;
  const int clamp_min = clamp_min_;
  // Invariant: idx is the current cell; steps_x + steps_y borders remain before the end cell.
  // Every cell before the end cell gets the miss update once per scan (the stamp), hits included
  // in the stamp so they are skipped.
  for (std::int64_t remaining = steps_x + steps_y; remaining > 0; --remaining) {
    Cell& cell = cells[idx];
    if (cell.stamp != stamp) {
      cell.stamp = stamp;
      const int v = (cell.value == kUnknown ? 0 : cell.value) + miss;
      cell.value = static_cast<std::int16_t>(std::max(v, clamp_min));
      ++updated;
    }
    // Exact ties (the ray through a corner) step in x, so the traversal stays 4-connected; the
    // step counts keep the last steps exact when the end point lies on a cell border. (A
    // branch-free form of this step measured slower: it lengthens the loop-carried chain.)
    if (steps_x != 0 && (steps_y == 0 || t_x <= t_y)) {
      idx += step_x;
      t_x += dt_x;
      --steps_x;
    } else {
      idx += step_idx_y;
      t_y += dt_y;
      --steps_y;
    }
  }
  return updated;
}

void DenseGrid::nextStamp() {
  if (++stamp_ == 0) {
    for (Cell& cell : cells_) cell.stamp = 0;
    stamp_ = 1;
  }
}

void DenseGrid::growToCover(std::int64_t min_x, std::int64_t min_y, std::int64_t max_x,
                            std::int64_t max_y) {
  const std::int64_t margin = params_.grow_margin_cells;
  if (width_ == 0) {
    origin_x_ = min_x - margin;
    origin_y_ = min_y - margin;
    width_ = max_x - min_x + 1 + 2 * margin;
    height_ = max_y - min_y + 1 + 2 * margin;
    cells_.assign(static_cast<std::size_t>(width_ * height_), Cell{kUnknown, 0});
    return;
  }
  if (min_x >= origin_x_ && min_y >= origin_y_ && max_x < origin_x_ + width_ &&
      max_y < origin_y_ + height_) {
    return;
  }
  // Grow each side that must grow by at least half the current size, so growth is amortised O(1)
  // per cell over a long run.
  const std::int64_t grow_x = std::max(margin, width_ / 2);
  const std::int64_t grow_y = std::max(margin, height_ / 2);
  std::int64_t new_min_x = origin_x_;
  std::int64_t new_min_y = origin_y_;
  std::int64_t new_max_x = origin_x_ + width_;  // exclusive
  std::int64_t new_max_y = origin_y_ + height_;
  if (min_x < new_min_x) new_min_x = std::min(min_x - margin, new_min_x - grow_x);
  if (min_y < new_min_y) new_min_y = std::min(min_y - margin, new_min_y - grow_y);
  if (max_x >= new_max_x) new_max_x = std::max(max_x + 1 + margin, new_max_x + grow_x);
  if (max_y >= new_max_y) new_max_y = std::max(max_y + 1 + margin, new_max_y + grow_y);
  const std::int64_t new_width = new_max_x - new_min_x;
  const std::int64_t new_height = new_max_y - new_min_y;
  std::vector<Cell> grown(static_cast<std::size_t>(new_width * new_height), Cell{kUnknown, 0});
  for (std::int64_t y = 0; y < height_; ++y) {
    const std::int64_t dst_row = (origin_y_ + y - new_min_y) * new_width + (origin_x_ - new_min_x);
    std::copy_n(cells_.begin() + y * width_, width_, grown.begin() + dst_row);
  }
  cells_.swap(grown);
  origin_x_ = new_min_x;
  origin_y_ = new_min_y;
  width_ = new_width;
  height_ = new_height;
}

void DenseGrid::reserve(const CellBox& box) {
  if (box.empty()) return;
  growToCover(box.min_x, box.min_y, box.max_x - 1, box.max_y - 1);
}

std::int16_t DenseGrid::rawValue(std::int64_t ix, std::int64_t iy) const {
  const std::int64_t x = ix - origin_x_;
  const std::int64_t y = iy - origin_y_;
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return kUnknown;
  return cells_[static_cast<std::size_t>(y * width_ + x)].value;
}

float DenseGrid::value(const CellIndex& cell) const {
  const std::int16_t v = rawValue(cell.x, cell.y);
  return v == kUnknown ? 0.0f : static_cast<float>(v) / static_cast<float>(kScale);
}

bool DenseGrid::isObserved(const CellIndex& cell) const {
  return rawValue(cell.x, cell.y) != kUnknown;
}

CellIndex DenseGrid::cellAt(double x, double y) const {
  return CellIndex{static_cast<std::int64_t>(std::floor(x * inv_resolution_)),
                   static_cast<std::int64_t>(std::floor(y * inv_resolution_))};
}

CellBox DenseGrid::extent() const {
  return CellBox{origin_x_, origin_y_, origin_x_ + width_, origin_y_ + height_};
}

std::uint64_t DenseGrid::countObserved() const {
  std::uint64_t count = 0;
  for (const Cell& cell : cells_) count += cell.value != kUnknown ? 1 : 0;
  return count;
}

std::size_t DenseGrid::bytes() const {
  return sizeof(*this) + cells_.capacity() * sizeof(Cell) +
         (dir_cos_.capacity() + dir_sin_.capacity() + end_fx_.capacity() + end_fy_.capacity()) *
             sizeof(double) +
         (end_x_.capacity() + end_y_.capacity()) * sizeof(std::int64_t) + kind_.capacity();
}

}  // namespace baseline
}  // namespace wavog
