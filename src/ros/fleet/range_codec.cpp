// RangeCodec (see range_codec.h).
#include "range_codec.h"

#include <algorithm>
#include <cmath>

#include "wavog_mapping/core/limits.h"

namespace wavog_fleet {

namespace {

// As the core's beam limits (classify/prepared_scan.cpp): the same expressions, the same values.
double givenReach(const wavog::MapParams& params, double range_max) {
  return params.sensor.max_range > 0 ? std::min(params.sensor.max_range, range_max) : range_max;
}

}  // namespace

double scanReach(const wavog::MapParams& params, double range_max, std::size_t count,
                 double angle_increment) {
  return std::min(givenReach(params, range_max),
                  wavog::hardRangeLimit(params, count, angle_increment));
}

double rangeStep(double reach, bool beyond) {
  return std::max(kRangeStep, reach / (beyond ? kMaxHitCode - 1 : kMaxHitCode));
}

bool RangeCodec::encode(const wavog::ScanView& view, const wavog::MapParams& params) {
  const double reach = scanReach(params, view.range_max, view.count, view.angle_increment);
  const double given = givenReach(params, view.range_max);
  const double step = rangeStep(reach, given > reach);
  const double range_min = view.range_min;
  if (!(reach > 0.0) || !std::isfinite(step) || !(range_min >= 0.0) ||
      !(range_min / step < kMaxHitCode)) {
    return false;
  }
  // The codes of a return: those that decode into [range_min, reach) and above 0, so that the core
  // takes a decoded return as a return, as it took the reading.
  const auto decoded = [step](long k) {
    return static_cast<double>(decodeRange(static_cast<std::uint16_t>(k), step));
  };
  long lo = std::max(1L, static_cast<long>(std::ceil(range_min / step)));
  while (lo <= kMaxHitCode && !(decoded(lo) >= range_min && decoded(lo) > 0.0)) ++lo;
  long hi = std::min(static_cast<long>(kMaxHitCode), static_cast<long>(std::floor(reach / step)));
  while (hi >= 1 && !(decoded(hi) < reach)) --hi;
  if (lo > hi) return false;
  // A reading at or beyond the reach but below range_max (max_range) is a no return the core
  // counts as beyond its hard limit (beams_beyond_limit). It gets the code above the returns' when
  // that decodes into [reach, given): the decoded scan counts it the same, and the map is the same
  // (every no return clears alike). Else, or without a hard limit below range_max, 65535.
  std::uint16_t beyond = kNoReturnCode;
  if (hi + 1 <= kMaxHitCode && decoded(hi + 1) >= reach && decoded(hi + 1) < given) {
    beyond = static_cast<std::uint16_t>(hi + 1);
  }
  step_ = step;
  codes_.resize(view.count);
  decoded_.resize(view.count);
  for (std::size_t j = 0; j < view.count; ++j) {
    const double z = view.ranges[j];
    std::uint16_t code = kNoReturnCode;
    // The core's classes (prepared_scan.cpp): invalid, no return, return.
    if (std::isnan(z) || z <= 0.0 || z < range_min) {  // -inf included
      code = kInvalidCode;
    } else if (z < reach) {
      code = static_cast<std::uint16_t>(std::clamp(std::lround(z / step), lo, hi));
    } else if (z < given) {
      code = beyond;
    }
    codes_[j] = code;
    decoded_[j] = decodeRange(code, step);
  }
  return true;
}

wavog::ScanView RangeCodec::decodedView(const wavog::ScanView& view) const {
  wavog::ScanView v = view;
  v.ranges = decoded_.data();
  v.count = decoded_.size();
  return v;
}

void decodeRanges(const std::uint16_t* codes, std::size_t count, double step,
                  std::vector<float>* out) {
  out->resize(count);
  for (std::size_t j = 0; j < count; ++j) (*out)[j] = decodeRange(codes[j], step);
}

}  // namespace wavog_fleet
