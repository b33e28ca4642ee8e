// Preparation of one scan for classification (see prepared_scan.h): validation, beam kinds and
// limits per REP 117, hit cells, sector boundary directions and the min / max table.
#include "classify/prepared_scan.h"

#include <atomic>
#include <limits>
#include <type_traits>

#include "update/worker_pool.h"
#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {
namespace detail {
namespace {

// The workers that help this thread's prepare() calls (PrepareHelpers).
thread_local WorkerPool* t_helpers = nullptr;

// Runs item(i) for every i in [0, items), on this thread and on the helpers that join, each
// taking the next item from a shared counter (so this thread alone can take them all).
template <typename Item>
void forEachItem(std::size_t items, Item item) {
  WorkerPool* pool = t_helpers;
  if (pool == nullptr || pool->threads() <= 1 || items <= 1) {
    for (std::size_t i = 0; i < items; ++i) item(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  pool->run([&](int) {
    for (std::size_t i = next.fetch_add(1, std::memory_order_relaxed); i < items;
         i = next.fetch_add(1, std::memory_order_relaxed)) {
      item(i);
    }
  });
}

// What a beam's reading says (REP 117): nothing (NaN, -inf, <= 0, below range_min), no return (at
// or beyond sensor_max, +inf), or a return.
enum class Reading : std::uint8_t { kNone, kNoReturn, kReturn };
Reading readingOf(double z, double range_min, double sensor_max) {
  if (std::isnan(z) || z == -std::numeric_limits<double>::infinity() || z <= 0.0 || z < range_min) {
    return Reading::kNone;
  }
  return z >= sensor_max ? Reading::kNoReturn : Reading::kReturn;
}
// The beam's E limit and the end of its occupied band (m): +inf / -inf when it has none.
void limitsOf(Reading r, double z, const BeamLimits& limits, double* ze, double* zu) {
  *ze = std::numeric_limits<double>::infinity();
  *zu = -std::numeric_limits<double>::infinity();
  if (r == Reading::kReturn) {
    *ze = z - limits.half_band;
    *zu = z + limits.half_band;
  } else if (r == Reading::kNoReturn && limits.clear > 0) {
    *ze = *zu = limits.clear;
  }
}

}  // namespace

PrepareHelpers::PrepareHelpers(WorkerPool* pool) : previous_(t_helpers) { t_helpers = pool; }
PrepareHelpers::~PrepareHelpers() { t_helpers = previous_; }

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
  sectors.prepare(n, amin, inc);
  setUnits();
  exact_ends_ = params.ndt;  // the Gaussians take the endpoints as the reference computes them
  sizeBuffers();
  // The per-beam work in pieces of kChunkBeams beams (their boundaries, endpoints, thresholds
  // and sorted hit keys), then the two tables (each over all beams), shared with the helpers;
  // every piece writes its own elements, so the result does not depend on who did which.
  // The piece that finishes last also merges the pieces' hit keys and counts the invalid beams
  // (while another participant may still build a table).
  const auto nu = static_cast<std::size_t>(n);
  const std::size_t chunks = (nu + kChunkBeams - 1) / kChunkBeams;
  tallies_.assign(chunks, ChunkTally{});
  runs_.resize(chunks);
  std::atomic<std::size_t> finished{0};
  forEachItem(chunks + 2, [&](std::size_t i) {
    if (i >= chunks) {
      buildTable(limits, scan.range_min, i == chunks);
      return;
    }
    const std::size_t lo = i * kChunkBeams, hi = std::min(nu, lo + kChunkBeams);
    setBoundaries(lo, i + 1 == chunks ? nu + 1 : hi);
    setBeams(limits, scan.range_min, lo, hi, &tallies_[i]);
    std::sort(hit_keys_.begin() + static_cast<std::ptrdiff_t>(lo),
              hit_keys_.begin() + static_cast<std::ptrdiff_t>(lo + tallies_[i].hits));
    // acq_rel: the last piece sees every other piece's keys and kinds.
    if (finished.fetch_add(1, std::memory_order_acq_rel) + 1 < chunks) return;
    mergeHits(chunks);
    invalid_prefix[0] = 0;
    for (std::size_t j = 0; j < nu; ++j) {
      invalid_prefix[j + 1] = invalid_prefix[j] + (kind[j] == BeamKind::kInvalid ? 1 : 0);
    }
  });
  reach = 0.0;
  for (const ChunkTally& t : tallies_) {
    st->beams_hit += t.hit;
    st->beams_no_return += t.no_return;
    st->beams_beyond_limit += t.beyond_limit;
    st->beams_invalid += t.invalid;
    reach = std::max(reach, t.reach);
  }
  if (invalid_prefix[nu] == n) return ScanStatus::kNoValidBeam;
  return ScanStatus::kOk;
}

void PreparedScan::sizeBuffers() {
  // Every element is written by setBoundaries(), setBeams() or buildTable() (a resize to the same
  // size touches nothing).
  const auto nu = static_cast<std::size_t>(n);
  bnd_x.resize(nu + 1);
  bnd_y.resize(nu + 1);
  kind.resize(nu);
  leaf.resize(nu + 1);
  leaf[nu] = LeafTest{};  // outside the fan: never E, never O
  hit_x.resize(nu);
  hit_y.resize(nu);
  hit_group.resize(nu);
  hit_bit.resize(nu);
  end_x.resize(nu);  // written for the hit beams only
  end_y.resize(nu);
  hit_keys_.resize(nu);
  hits.resize(nu);  // mergeHits() writes at most nu keys
  invalid_prefix.resize(nu + 1);
  const std::size_t size = static_cast<std::size_t>(tableLevels()) * nu;
  min_e2.resize(size);
  max_u2.resize(size);
  group_x0 = static_cast<std::int64_t>(std::floor(px / res)) >> 2;
  group_y0 = static_cast<std::int64_t>(std::floor(py / res)) >> 2;
}

void PreparedScan::mergeHits(std::size_t chunks) {
  // The pieces' sorted runs of hit keys, merged pairwise (hit_keys_ and hits taking turns as the
  // source), then made unique: the same as sorting all of them.
  std::vector<std::pair<std::size_t, std::size_t>>& runs = runs_;  // [begin, end)
  runs.resize(chunks);  // sized by prepare(): no allocation here
  std::size_t total = 0;
  for (std::size_t c = 0; c < chunks; ++c) {
    runs[c] = {c * kChunkBeams, c * kChunkBeams + tallies_[c].hits};
    total += tallies_[c].hits;
  }
  std::vector<std::uint64_t>* from = &hit_keys_;
  std::vector<std::uint64_t>* to = &hits;
  do {
    const std::uint64_t* in = from->data();
    std::uint64_t* const out = to->data();
    std::uint64_t* end = out;
    std::size_t merged = 0;
    for (std::size_t r = 0; r < runs.size(); r += 2) {
      std::uint64_t* const begin = end;
      if (r + 1 < runs.size()) {
        end = std::merge(in + runs[r].first, in + runs[r].second, in + runs[r + 1].first,
                         in + runs[r + 1].second, end);
      } else {
        end = std::copy(in + runs[r].first, in + runs[r].second, end);
      }
      runs[merged++] = {static_cast<std::size_t>(begin - out), static_cast<std::size_t>(end - out)};
    }
    runs.resize(merged);
    std::swap(from, to);
  } while (runs.size() > 1);
  if (from != &hits) hits.swap(hit_keys_);  // the merged keys end in `hits`
  hits.resize(total);
  hits.erase(std::unique(hits.begin(), hits.end()), hits.end());
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

void PreparedScan::setBoundaries(std::size_t lo, std::size_t hi) {
  // Boundary k points along theta + amin + (k - 1/2) inc. Rotating by inc from a direction
  // computed with sin and cos every kBoundaryAnchor boundaries spares a sin and a cos per beam;
  // it drifts by under 1e-12 rad (4e-13 worst, measured for steps from 1e-6 to 2.1 rad), far
  // inside kRayMargin. A range starts at an anchor (kChunkBeams is a multiple of it), so the
  // boundaries are the same however the ranges are cut.
  constexpr std::size_t kBoundaryAnchor = 64;
  static_assert(kChunkBeams % kBoundaryAnchor == 0, "pieces start at an anchor");
  const double step_c = std::cos(inc), step_s = std::sin(inc);
  for (std::size_t k = lo; k < hi; ++k) {
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

void PreparedScan::setBeams(const BeamLimits& limits, double range_min, std::size_t lo,
                            std::size_t hi, ChunkTally* tally) {
  // The rotated endpoint differs from the reference's by under 2^-53 (|theta| + |bearing|) z for
  // the rounding of theta + bearing plus a few ulps of |p| + z (cos, sin, products; 1e-15 each
  // bounds them): a guard of 1e-12 of those, in cells, around a cell edge leaves a 1000-fold
  // margin.
  const double angle_scale = std::fabs(theta) + std::fabs(amin) + 8.0;
  const double end_offset = std::fabs(px) + std::fabs(py);
  std::uint64_t* keys = hit_keys_.data() + lo;
  for (std::size_t j = lo; j < hi; ++j) {
    const double z = ranges_[j];
    const Reading r = readingOf(z, range_min, limits.sensor_max);
    double ze, zu;  // E limit and end of the occupied band (m)
    limitsOf(r, z, limits, &ze, &zu);
    BeamKind k = BeamKind::kInvalid;
    hit_x[j] = hit_y[j] = 0;
    hit_group[j] = hit_bit[j] = 0;
    if (r == Reading::kNone) {
      ++tally->invalid;
    } else if (r == Reading::kNoReturn) {  // +inf and out-of-range readings (REP 117)
      ++tally->no_return;
      if (z < limits.given) ++tally->beyond_limit;  // a return but for the hard limit
      if (limits.clear > 0) k = BeamKind::kClear;
    } else {
      ++tally->hit;
      k = BeamKind::kHit;
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
      keys[tally->hits++] = cellKey(hit_x[j], hit_y[j]);
      hit_group[j] = groupKey(hit_x[j], hit_y[j]);
      hit_bit[j] = 1u << ((hit_x[j] & 3) + 4 * (hit_y[j] & 3));
    }
    kind[j] = k;
    const bool valid = k != BeamKind::kInvalid;
    leaf[j].e = valid ? sqrtBelow(ze) : -1.0;
    leaf[j].o = k == BeamKind::kHit ? sqrtAtMost(zu) : -1.0;
    if (valid) tally->reach = std::max(tally->reach, zu);
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

int PreparedScan::tableLevels() const {
  int levels = 1;
  while ((1 << levels) <= n) ++levels;
  return levels;
}

void PreparedScan::buildTable(const BeamLimits& limits, double range_min, bool empty) {
  // Level 0: each beam's squared limit (E limit or end of the occupied band); level k holds the
  // min / max over [j, j + 2^k).
  const auto nu = static_cast<std::size_t>(n);
  double* t = empty ? min_e2.data() : max_u2.data();
  // limitsOf(readingOf(z)) as selects (NaN and -inf fail z > 0): no branch per beam.
  const double none =
      empty ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  const double band = empty ? -limits.half_band : limits.half_band;
  const double no_return = limits.clear > 0 ? limits.clear : none;
  for (std::size_t j = 0; j < nu; ++j) {
    const double z = ranges_[j];
    const bool reading = z > 0.0 && z >= range_min;
    const double limit = reading ? (z < limits.sensor_max ? z + band : no_return) : none;
    t[j] = squaredLimit(limit);
  }
  const auto levelsBy = [&](auto pick) {
    const int levels = tableLevels();
    for (int k = 1; k < levels; ++k) {
      const std::size_t base = static_cast<std::size_t>(k) * nu, prev = base - nu;
      const std::size_t half = std::size_t{1} << (k - 1);
      for (std::size_t j = 0; j + (std::size_t{1} << k) <= nu; ++j) {
        t[base + j] = pick(t[prev + j], t[prev + j + half]);
      }
    }
  };
  if (empty) {
    levelsBy([](double a, double b) { return std::min(a, b); });
  } else {
    levelsBy([](double a, double b) { return std::max(a, b); });
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
  release(hit_keys_);
  release(tallies_);
  release(runs_);
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
