#include "dense_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <utility>

#include "wavog_mapping/core/limits.h"

namespace wavog_test {

using wavog::PolicyType;

namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

DenseReference::DenseReference(const wavog::MapParams& params, const wavog::CellBox& extent)
    : DenseReference(std::vector<wavog::MapParams>{params}, extent) {}

DenseReference::DenseReference(const std::vector<wavog::MapParams>& layers,
                               const wavog::CellBox& extent)
    : layers_(layers), p_(layers.at(0)), extent_(extent) {
  const auto n = static_cast<std::size_t>(extent.width() * extent.height());
  for (const auto& p : layers_) {
    if (p.grid.resolution != p_.grid.resolution || p.sensor.band_width != p_.sensor.band_width ||
        p.sensor.max_range != p_.sensor.max_range ||
        p.sensor.no_return_clear != p_.sensor.no_return_clear) {
      throw std::invalid_argument("reference layers must share the scan geometry");
    }
    v_.emplace_back(n, p.initValue());
  }
  known_.assign(n, 0);
}

std::size_t DenseReference::index(std::int64_t ix, std::int64_t iy) const {
  if (ix < extent_.min_x || ix >= extent_.max_x || iy < extent_.min_y || iy >= extent_.max_y) {
    throw std::out_of_range("cell outside the reference extent");
  }
  return static_cast<std::size_t>((iy - extent_.min_y) * extent_.width() + (ix - extent_.min_x));
}

double DenseReference::apply(const wavog::MapParams& p, bool occupied, double x) {
  const double o = occupied ? p.sensor.odd_occ : p.sensor.odd_emp;
  const double lo = p.policy.clamp_min, hi = p.policy.clamp_max, g = p.policy.gamma;
  switch (p.policy.type) {
    case PolicyType::kNone:
      return x + o;  // eq. 1.2
    case PolicyType::kMax:
      return std::max(x, o);  // eq. 1.4
    case PolicyType::kClamp:
      return std::max(std::min(x + o, hi), lo);  // eq. 1.5
    case PolicyType::kForget:
      return (1.0 - g) * x + g * o;  // eq. 1.6
    case PolicyType::kClampLower:
      return std::max(x + o, lo);
    case PolicyType::kClampUpper:
      return std::min(x + o, hi);
  }
  return x;
}

bool ReferenceClassifier::prepare(const wavog::MapParams& p, const wavog::Pose2& pose,
                                  const wavog::ScanView& scan) {
  // Scans the core refuses change nothing.
  if (scan.count == 0 || !(std::fabs(scan.angle_min) <= wavog::kMaxAbsAngleMin) ||
      !std::isfinite(scan.angle_increment) ||
      !(std::fabs(scan.angle_increment) >= wavog::kMinAbsAngleIncrement) ||
      scan.count > wavog::kMaxBeams || !std::isfinite(scan.range_min) || scan.range_min < 0 ||
      !(scan.range_max > scan.range_min) ||
      std::fabs(scan.angle_increment) * static_cast<double>(scan.count) > 2 * kPi + 1e-6 ||
      !std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return false;
  }
  pose_ = pose;
  n_ = static_cast<int>(scan.count);
  std::vector<double> ranges(scan.ranges, scan.ranges + n_);
  amin_ = scan.angle_min;
  inc_ = scan.angle_increment;
  if (inc_ < 0) {
    amin_ = scan.angle_min + scan.angle_increment * (static_cast<double>(n_) - 1.0);
    inc_ = -inc_;
    std::reverse(ranges.begin(), ranges.end());
  }
  const double amax = amin_ + inc_ * (static_cast<double>(n_) - 1.0);
  seam_ = 0.5 * (amin_ + amax) - kPi;
  res_ = p.grid.resolution;
  // The hard range limit (limits.h) caps the range limit and the no-return clearing distance.
  const double hard = wavog::hardRangeLimit(p, scan.count, scan.angle_increment);
  const double sensor_max = std::min(
      p.sensor.max_range > 0 ? std::min(p.sensor.max_range, scan.range_max) : scan.range_max, hard);
  const double clear = std::min(p.sensor.no_return_clear, hard);
  const double half_band = 0.5 * (p.sensor.band_width > 0 ? p.sensor.band_width : res_);
  const double inf = std::numeric_limits<double>::infinity();

  // Per beam: 0 invalid, 1 hit, 2 clearing no-return; E limit and band end.
  kind_.assign(static_cast<std::size_t>(n_), 0);
  ze_.assign(static_cast<std::size_t>(n_), inf);
  zu_.assign(static_cast<std::size_t>(n_), -inf);
  hits_.clear();
  bool any_valid = false;
  for (int j = 0; j < n_; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const double z = ranges[ju];
    if (std::isnan(z) || z == -inf || z <= 0 || z < scan.range_min) continue;
    if (z >= sensor_max) {
      if (clear > 0) {
        kind_[ju] = 2;
        ze_[ju] = zu_[ju] = clear;
        any_valid = true;
      }
      continue;
    }
    kind_[ju] = 1;
    any_valid = true;
    ze_[ju] = z - half_band;
    zu_[ju] = z + half_band;
    const double bearing = pose.theta + (amin_ + static_cast<double>(j) * inc_);
    const double ex = pose.x + z * std::cos(bearing), ey = pose.y + z * std::sin(bearing);
    hits_.emplace(static_cast<std::int64_t>(std::floor(ex / res_)),
                  static_cast<std::int64_t>(std::floor(ey / res_)));
  }
  reach_ = 0;
  for (int j = 0; j < n_; ++j) reach_ = std::max(reach_, zu_[static_cast<std::size_t>(j)]);
  return any_valid;
}

std::vector<std::pair<double, double>> ReferenceClassifier::endpoints(
    const wavog::Pose2& pose, const wavog::ScanView& scan) const {
  std::vector<std::pair<double, double>> out;
  std::vector<double> ranges(scan.ranges, scan.ranges + n_);
  if (scan.angle_increment < 0) std::reverse(ranges.begin(), ranges.end());
  for (int j = 0; j < n_; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    if (kind_[ju] != 1) continue;
    const double z = ranges[ju];
    const double bearing = pose.theta + (amin_ + static_cast<double>(j) * inc_);
    out.emplace_back(pose.x + z * std::cos(bearing), pose.y + z * std::sin(bearing));
  }
  return out;
}

wavog::CellClass ReferenceClassifier::cellClass(std::int64_t ix, std::int64_t iy) const {
  if (hits_.count({ix, iy})) return wavog::CellClass::kOccupied;
  const double dx = (static_cast<double>(ix) + 0.5) * res_ - pose_.x;
  const double dy = (static_cast<double>(iy) + 0.5) * res_ - pose_.y;
  const double rho = std::sqrt(dx * dx + dy * dy);
  double beta = std::atan2(dy, dx) - pose_.theta;
  beta -= 2 * kPi * std::floor((beta - seam_) / (2 * kPi));
  const long j = std::lround((beta - amin_) / inc_);
  if (j < 0 || j >= n_ || kind_[static_cast<std::size_t>(j)] == 0)
    return wavog::CellClass::kUnknown;
  const auto ju = static_cast<std::size_t>(j);
  if (rho < ze_[ju]) return wavog::CellClass::kEmpty;
  if (kind_[ju] == 1 && rho <= zu_[ju]) return wavog::CellClass::kOccupied;
  return wavog::CellClass::kUnknown;
}

void DenseReference::integrate(const wavog::Pose2& pose, const wavog::ScanView& scan,
                               std::size_t repeat) {
  last_updated_ = 0;
  ReferenceClassifier ref;
  if (!ref.prepare(p_, pose, scan)) return;
  // Cells farther than every band end are U: visit only the box of radius `reach` (plus a cell).
  const double reach = ref.reach(), res = p_.grid.resolution;
  const auto x_lo =
      std::max(extent_.min_x, static_cast<std::int64_t>(std::floor((pose.x - reach) / res)) - 1);
  const auto x_hi =
      std::min(extent_.max_x, static_cast<std::int64_t>(std::floor((pose.x + reach) / res)) + 2);
  const auto y_lo =
      std::max(extent_.min_y, static_cast<std::int64_t>(std::floor((pose.y - reach) / res)) - 1);
  const auto y_hi =
      std::min(extent_.max_y, static_cast<std::int64_t>(std::floor((pose.y + reach) / res)) + 2);
  for (std::int64_t iy = y_lo; iy < y_hi; ++iy) {
    for (std::int64_t ix = x_lo; ix < x_hi; ++ix) {
      const wavog::CellClass cls = ref.cellClass(ix, iy);
      if (cls == wavog::CellClass::kUnknown) continue;
      const bool occupied = cls == wavog::CellClass::kOccupied;
      const std::size_t i = index(ix, iy);
      for (std::size_t r = 0; r < repeat; ++r) {
        for (std::size_t k = 0; k < layers_.size(); ++k)
          v_[k][i] = apply(layers_[k], occupied, v_[k][i]);
        if (v_.size() >= 2 && v_[0][i] + v_[1][i] > sum_bound_) {
          const double f = sum_bound_ / (v_[0][i] + v_[1][i]);
          v_[0][i] *= f;
          v_[1][i] *= f;
        }
        if (occupancy_layer_ < v_.size() && v_[0][i] > 0.0 &&
            v_[occupancy_layer_][i] <= empty_bound_ + 1e-5) {
          v_[0][i] = 0.0;
          v_[1][i] = sum_bound_;
        }
      }
      known_[i] = 1;
      ++last_updated_;
    }
  }
  if (p_.ndt) {
    if (repeat != 1) throw std::invalid_argument("DenseReference: NDT cells integrate once");
    integrateNdt(ref, pose, scan);
  }
}

// Normal-distribution cells (MapParams::ndt) of layer 0: every observed cell's moments forget by
// 1 - gamma ("forget"), then each end-point adds itself with weight gamma (1 for the other
// policies), the clamp policies cap the weight, and the cells the scan changed that weigh less
// than ndt_min_weight of its end-points (ndt_min_weight times that weight) are dropped.
void DenseReference::integrateNdt(const ReferenceClassifier& ref, const wavog::Pose2& pose,
                                  const wavog::ScanView& scan) {
  const wavog::MapParams& p = layers_.at(0);
  const bool forget = p.policy.type == PolicyType::kForget;
  const double g = forget ? p.policy.gamma : 1.0;
  // The cells whose weight the scan changes: the observed ones (forgetting) and the touched ones.
  std::set<std::pair<std::int64_t, std::int64_t>> changed, touched;
  if (forget) {
    for (auto& kv : ndt_) {
      const wavog::CellClass cls = ref.cellClass(kv.first.second, kv.first.first);
      if (cls == wavog::CellClass::kUnknown) continue;
      Moments& m = kv.second;
      for (double* v : {&m.w, &m.x, &m.y, &m.xx, &m.xy, &m.yy}) *v *= 1.0 - g;
      changed.insert(kv.first);
    }
  }
  // The end-points, in the core's beam order (ascending bearing).
  std::vector<std::pair<double, double>> points = ref.endpoints(pose, scan);
  const double res = p.grid.resolution;
  for (const auto& e : points) {
    const std::pair<std::int64_t, std::int64_t> key{
        static_cast<std::int64_t>(std::floor(e.second / res)),
        static_cast<std::int64_t>(std::floor(e.first / res))};
    Moments& m = ndt_[key];
    m.w += g;
    m.x += g * e.first;
    m.y += g * e.second;
    m.xx += g * e.first * e.first;
    m.xy += g * e.first * e.second;
    m.yy += g * e.second * e.second;
    touched.insert(key);
  }
  if (p.policy.type == PolicyType::kClamp || p.policy.type == PolicyType::kClampUpper) {
    for (const auto& key : touched) {
      Moments& m = ndt_[key];
      if (m.w <= p.ndt_max_weight) continue;
      const double f = p.ndt_max_weight / m.w;
      for (double* v : {&m.w, &m.x, &m.y, &m.xx, &m.xy, &m.yy}) *v *= f;
    }
  }
  changed.insert(touched.begin(), touched.end());
  for (const auto& key : changed) {
    const auto it = ndt_.find(key);
    if (!(it->second.w >= p.ndt_min_weight * g && it->second.w > 0.0)) ndt_.erase(it);
  }
}

wavog::NdtCell DenseReference::gaussian(const Moments& m) {
  wavog::NdtCell c;
  c.weight = m.w;
  c.mean_x = m.x / m.w;
  c.mean_y = m.y / m.w;
  c.cov_xx = m.xx / m.w - c.mean_x * c.mean_x;
  c.cov_xy = m.xy / m.w - c.mean_x * c.mean_y;
  c.cov_yy = m.yy / m.w - c.mean_y * c.mean_y;
  return c;
}

bool DenseReference::ndtCell(std::int64_t ix, std::int64_t iy, wavog::NdtCell* out) const {
  const auto it = ndt_.find({iy, ix});
  if (it == ndt_.end()) return false;
  *out = gaussian(it->second);
  out->ix = ix;
  out->iy = iy;
  return true;
}

std::vector<wavog::NdtCell> DenseReference::ndtLayer(int s, const wavog::CellBox& window) const {
  std::map<std::pair<std::int64_t, std::int64_t>, Moments> merged;
  for (const auto& kv : ndt_) {
    const std::int64_t cx = kv.first.second >> s, cy = kv.first.first >> s;
    if (cx < window.min_x || cx >= window.max_x || cy < window.min_y || cy >= window.max_y)
      continue;
    Moments& m = merged[{cy, cx}];
    m.w += kv.second.w;
    m.x += kv.second.x;
    m.y += kv.second.y;
    m.xx += kv.second.xx;
    m.xy += kv.second.xy;
    m.yy += kv.second.yy;
  }
  std::vector<wavog::NdtCell> out;
  for (const auto& kv : merged) {
    wavog::NdtCell c = gaussian(kv.second);
    c.ix = kv.first.second;
    c.iy = kv.first.first;
    out.push_back(c);
  }
  return out;
}

double DenseReference::blockMean(int s, std::int64_t bx, std::int64_t by) const {
  const std::int64_t size = std::int64_t{1} << s;
  double sum = 0;
  for (std::int64_t y = by * size; y < (by + 1) * size; ++y)
    for (std::int64_t x = bx * size; x < (bx + 1) * size; ++x) sum += value(x, y);
  return sum / static_cast<double>(size * size);
}

double DenseReference::blockMaxObserved(int s, std::int64_t bx, std::int64_t by) const {
  const std::int64_t size = std::int64_t{1} << s;
  double best = -std::numeric_limits<double>::infinity();
  for (std::int64_t y = by * size; y < (by + 1) * size; ++y)
    for (std::int64_t x = bx * size; x < (bx + 1) * size; ++x)
      if (known(x, y)) best = std::max(best, value(x, y));
  return best;
}

bool DenseReference::blockAnyKnown(int s, std::int64_t bx, std::int64_t by) const {
  const std::int64_t size = std::int64_t{1} << s;
  for (std::int64_t y = by * size; y < (by + 1) * size; ++y)
    for (std::int64_t x = bx * size; x < (bx + 1) * size; ++x)
      if (known(x, y)) return true;
  return false;
}

}  // namespace wavog_test
