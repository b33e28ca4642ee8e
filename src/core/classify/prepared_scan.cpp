// Preparation of one scan for classification (see prepared_scan.h): validation, beam kinds and
// limits per REP 117, hit cells, sector boundary directions and the min / max table.
#include "classify/prepared_scan.h"

#include <limits>
#include <type_traits>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace detail {

ScanStatus checkScan(const Pose2& pose, const ScanView& scan) {
  if (scan.count == 0 || scan.ranges == nullptr) return ScanStatus::kEmpty;
  const double n_beams = static_cast<double>(scan.count);
  // The negated comparisons also refuse NaN.
  if (!(std::fabs(scan.angle_min) <= kMaxAbsAngleMin) ||
      !(std::fabs(scan.angle_increment) >= kMinAbsAngleIncrement) ||
      !std::isfinite(scan.angle_increment) || !std::isfinite(scan.range_min) ||
      scan.range_min < 0.0 || !(scan.range_max > scan.range_min) || std::isnan(scan.range_max) ||
      std::fabs(scan.angle_increment) * n_beams > kTwoPi + 1e-6 || scan.count > kMaxBeams) {
    return ScanStatus::kBadGeometry;
  }
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return ScanStatus::kBadPose;
  }
  return ScanStatus::kOk;
}

bool reachInExtent(const Pose2& pose, const BeamLimits& limits, double resolution) {
  const double max_reach = std::max(limits.sensor_max + limits.half_band, limits.clear);
  const double extent = static_cast<double>(kCellIndexLimit) - 2.0;
  return (std::fabs(pose.x) + max_reach) / resolution < extent &&
         (std::fabs(pose.y) + max_reach) / resolution < extent;
}

ScanStatus PreparedScan::prepare(const MapParams& params, const Pose2& pose, const ScanView& scan,
                                 IntegrateStats* st) {
  const ScanStatus status = checkScan(pose, scan);
  if (status != ScanStatus::kOk) return status;
  const BeamLimits limits = beamLimits(params, scan);
  // Every cell the scan may touch (hit cells, the reach box, the block loop) lies within the
  // largest reach of the pose.
  if (!reachInExtent(pose, limits, params.grid.resolution)) return ScanStatus::kOutOfExtent;
  const double cell = params.grid.resolution;
  setGeometry(pose, scan, cell);
  setBoundaries();
  sectors.prepare(n, amin, inc);
  setUnits();
  exact_ends_ = params.ndt;  // the Gaussians take the endpoints as the reference computes them
  setBeams(limits, scan, st);
  if (invalid_prefix[static_cast<std::size_t>(n)] == n) return ScanStatus::kNoValidBeam;
  std::sort(hits.begin(), hits.end());
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
  buildTables();
  return ScanStatus::kOk;
}

void PreparedScan::setGeometry(const Pose2& pose, const ScanView& scan, double resolution) {
  n = static_cast<int>(scan.count);
  const double n_beams = static_cast<double>(scan.count);
  px = pose.x;
  py = pose.y;
  theta = pose.theta;
  res = resolution;
  ranges_.assign(scan.ranges, scan.ranges + n);
  if (scan.angle_increment > 0) {
    amin = scan.angle_min;
    inc = scan.angle_increment;
  } else {  // same beams, ascending bearings
    amin = scan.angle_min + scan.angle_increment * (n_beams - 1.0);
    inc = -scan.angle_increment;
    std::reverse(ranges_.begin(), ranges_.end());
  }
  const double amax = amin + inc * (n_beams - 1.0);
  seam = 0.5 * (amin + amax) - kPi;
  fast_guard = kFastAtanError / inc + kIndexSlack;
  seam_map = std::remainder(theta + seam, kTwoPi);
  cos_theta = std::cos(theta);
  sin_theta = std::sin(theta);
  inv_inc = 1.0 / inc;
  t_seam = (seam - amin) / inc;
}

void PreparedScan::setBoundaries() {
  const auto nu = static_cast<std::size_t>(n);
  bnd_x.resize(nu + 1);
  bnd_y.resize(nu + 1);
  // Boundary k points along theta + amin + (k - 1/2) inc. Rotating by inc from a direction
  // computed with sin and cos every kBoundaryAnchor boundaries spares a sin and a cos per beam;
  // it drifts by under 1e-12 rad (4e-13 worst, measured for steps from 1e-6 to 2.1 rad), far
  // inside kRayMargin.
  constexpr std::size_t kBoundaryAnchor = 64;
  const double step_c = std::cos(inc), step_s = std::sin(inc);
  for (std::size_t k = 0; k <= nu; ++k) {
    if (k % kBoundaryAnchor == 0) {
      const double b = theta + amin + (static_cast<double>(k) - 0.5) * inc;
      bnd_x[k] = std::cos(b);
      bnd_y[k] = std::sin(b);
    } else {
      const double c = bnd_x[k - 1], s = bnd_y[k - 1];
      bnd_x[k] = c * step_c - s * step_s;
      bnd_y[k] = s * step_c + c * step_s;
    }
  }
}

BeamLimits beamLimits(const MapParams& params, const ScanView& scan) {
  // The hard limit caps range_max (+inf is allowed by REP 117) and no_return_clear, so one scan's
  // reach, and with it the blocks and cells it may touch, is bounded (limits.h).
  const double hard = hardRangeLimit(params, scan.count, scan.angle_increment);
  const double given = params.sensor.max_range > 0
                           ? std::min(params.sensor.max_range, scan.range_max)
                           : scan.range_max;
  BeamLimits limits;
  limits.given = given;
  limits.sensor_max = std::min(given, hard);
  limits.clear = std::min(params.sensor.no_return_clear, hard);
  limits.half_band =
      0.5 * (params.sensor.band_width > 0 ? params.sensor.band_width : params.grid.resolution);
  return limits;
}

void PreparedScan::setBeams(const BeamLimits& limits, const ScanView& scan, IntegrateStats* st) {
  const auto nu = static_cast<std::size_t>(n);
  const double sensor_max = limits.sensor_max;
  const double half_band = limits.half_band;
  const double clear = limits.clear;
  const double inf = std::numeric_limits<double>::infinity();
  kind.assign(nu, BeamKind::kInvalid);
  leaf.resize(nu + 1);    // every element is written below
  leaf[nu] = LeafTest{};  // outside the fan: never E, never O
  // Level 0 of the tables is written below, the levels above by buildTables(). Sized once per
  // scan without clearing (a resize to the same size touches nothing).
  tableLevels();
  invalid_prefix.assign(nu + 1, 0);
  hits.clear();
  hit_x.assign(nu, 0);
  hit_y.assign(nu, 0);
  hit_group.assign(nu, 0);
  hit_bit.assign(nu, 0);
  group_x0 = static_cast<std::int64_t>(std::floor(px / res)) >> 2;
  group_y0 = static_cast<std::int64_t>(std::floor(py / res)) >> 2;
  end_x.resize(nu);  // written for the hit beams below
  end_y.resize(nu);
  reach = 0.0;
  // The rotated endpoint differs from the reference's by under 2^-53 (|theta| + |bearing|) z for
  // the rounding of theta + bearing plus a few ulps of |p| + z (cos, sin, products; 1e-15 each
  // bounds them): a guard of 1e-12 of those, in cells, around a cell edge leaves a 1000-fold
  // margin.
  const double angle_scale = std::fabs(theta) + std::fabs(amin) + 8.0;
  const double end_offset = std::fabs(px) + std::fabs(py);
  for (std::size_t j = 0; j < nu; ++j) {
    const double z = ranges_[j];
    double ze = inf, zu = -inf;  // E limit and end of the occupied band (m)
    if (std::isnan(z) || z == -inf || z <= 0.0 || z < scan.range_min) {
      ++st->beams_invalid;
    } else if (z >= sensor_max) {  // +inf and out-of-range readings: no return (REP 117)
      ++st->beams_no_return;
      if (z < limits.given) ++st->beams_beyond_limit;  // a return but for the hard limit
      if (clear > 0) {
        kind[j] = BeamKind::kClear;
        ze = zu = clear;
      }
    } else {
      ++st->beams_hit;
      kind[j] = BeamKind::kHit;
      ze = z - half_band;
      zu = z + half_band;
      // The endpoint from the beam's unit vector rotated by the pose (a few ulps from the
      // reference's cos / sin of theta + bearing); the reference's own arithmetic when its
      // cell could differ, or when the endpoint itself is used (exact_ends_).
      double ex = px + z * (cos_theta * unit_c_[j] - sin_theta * unit_s_[j]);
      double ey = py + z * (sin_theta * unit_c_[j] + cos_theta * unit_s_[j]);
      double ux = ex / res, uy = ey / res;
      double fx = fastFloor(ux), fy = fastFloor(uy);
      const double guard = 1e-12 * (1.0 + (end_offset + z + z * angle_scale) / res);
      if (exact_ends_ || !(ux - fx > guard) || !(fx + 1.0 - ux > guard) || !(uy - fy > guard) ||
          !(fy + 1.0 - uy > guard)) {
        const double bearing = theta + (amin + static_cast<double>(j) * inc);
        ex = px + z * std::cos(bearing);
        ey = py + z * std::sin(bearing);
        fx = std::floor(ex / res);
        fy = std::floor(ey / res);
      }
      end_x[j] = ex;
      end_y[j] = ey;
      hit_x[j] = static_cast<std::int64_t>(fx);
      hit_y[j] = static_cast<std::int64_t>(fy);
      hits.push_back(cellKey(hit_x[j], hit_y[j]));
      hit_group[j] = groupKey(hit_x[j], hit_y[j]);
      hit_bit[j] = 1u << ((hit_x[j] & 3) + 4 * (hit_y[j] & 3));
    }
    const bool valid = kind[j] != BeamKind::kInvalid;
    min_e2[j] = squaredLimit(ze);
    max_u2[j] = squaredLimit(zu);
    leaf[j].e = valid ? sqrtBelow(ze) : -1.0;
    leaf[j].o = kind[j] == BeamKind::kHit ? sqrtAtMost(zu) : -1.0;
    if (valid) reach = std::max(reach, zu);
    invalid_prefix[j + 1] = invalid_prefix[j] + (valid ? 0 : 1);
  }
}

void PreparedScan::setUnits() {
  if (n == units_n_ && amin == units_amin_ && inc == units_inc_) return;
  const auto nu = static_cast<std::size_t>(n);
  unit_c_.resize(nu);
  unit_s_.resize(nu);
  for (std::size_t j = 0; j < nu; ++j) {
    const double a = amin + static_cast<double>(j) * inc;
    unit_c_[j] = std::cos(a);
    unit_s_[j] = std::sin(a);
  }
  units_n_ = n;
  units_amin_ = amin;
  units_inc_ = inc;
}

int PreparedScan::tableLevels() {
  int levels = 1;
  while ((1 << levels) <= n) ++levels;
  const std::size_t size = static_cast<std::size_t>(levels) * static_cast<std::size_t>(n);
  min_e2.resize(size);
  max_u2.resize(size);
  return levels;
}

void PreparedScan::buildTables() {
  // Level k holds min / max over [j, j + 2^k); level 0 is filled by setBeams().
  const auto nu = static_cast<std::size_t>(n);
  const int levels = tableLevels();
  for (int k = 1; k < levels; ++k) {
    const std::size_t base = static_cast<std::size_t>(k) * nu, prev = base - nu;
    const std::size_t half = std::size_t{1} << (k - 1);
    for (std::size_t j = 0; j + (std::size_t{1} << k) <= nu; ++j) {
      min_e2[base + j] = std::min(min_e2[prev + j], min_e2[prev + j + half]);
      max_u2[base + j] = std::max(max_u2[prev + j], max_u2[prev + j + half]);
    }
  }
}

void PreparedScan::releaseIfLarge() {
  if (sectors.buckets() > kKeepBuckets) sectors.release();
  if (ranges_.capacity() <= kScratchKeepBeams) return;
  const auto release = [](auto& v) { std::decay_t<decltype(v)>().swap(v); };
  release(ranges_);
  release(unit_c_);
  release(unit_s_);
  units_n_ = -1;
  release(kind);
  release(leaf);
  release(hit_x);
  release(end_x);
  release(end_y);
  release(hit_y);
  release(hits);
  release(invalid_prefix);
  release(min_e2);
  release(max_u2);
  release(bnd_x);
  release(bnd_y);
  release(hit_group);
  release(hit_bit);
}

}  // namespace detail
}  // namespace wavog
