// RangeCodec: a scan's ranges as 16-bit codes for the fleet stream (PlacedScan version 2,
// fleet_stream_format: uint16). A mapper encodes the ranges it is about to integrate and then
// integrates the decoded values, so its own map and a fleet node's (which decodes the same codes
// with the same decodeRange()) see the very same floats: the merge rule stays exact.
//
// Codes: kInvalidCode (0) for a reading the core takes as invalid (NaN, -inf, <= 0, below
// range_min), decoded as NaN; kNoReturnCode (65535) for a reading at or beyond the scan's reach
// (+inf, range_max, the core's limits), decoded as +inf; k in [1, kMaxHitCode] for a return,
// decoded as float(k * step). The step is kRangeStep (1 mm), or reach / kMaxHitCode for a scan
// reaching farther than 65.534 m (reach / (kMaxHitCode - 1) when the hard limit binds, below), so that every return below the reach keeps a code, and a return
// always decodes to a return: within [range_min, reach). A reading beyond the core's hard limit
// but below range_max takes the code just above the returns' when it decodes into that interval,
// so that the core counts it as beyond its limit on both sides (beams_beyond_limit); it is a no
// return like any other. ROS-free; not thread-safe (one per caller).
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_RANGE_CODEC_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_RANGE_CODEC_H_

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog_fleet {

constexpr std::uint16_t kInvalidCode = 0;
constexpr std::uint16_t kNoReturnCode = 65535;
constexpr std::uint16_t kMaxHitCode = 65534;
/// The finest step (m) of the codes; scans reaching farther than kMaxHitCode steps get a coarser
/// one (rangeStep()).
constexpr double kRangeStep = 0.001;
/// Largest step (m) a fleet node takes: above any a mapper sends (at most kMaxRangeCells cells of
/// the largest resolution, 100 m, over kMaxHitCode: 100.003 m).
constexpr double kMaxRangeStep = 128.0;

/// The reach (m) of a scan of `count` beams `angle_increment` apart with limit `range_max` on a
/// map of `params`: a reading at or beyond it is a no return for the core (max_range, range_max,
/// hardRangeLimit()).
double scanReach(const wavog::MapParams& params, double range_max, std::size_t count,
                 double angle_increment);
/// The step (m) for a scan of that reach: kRangeStep, or reach / kMaxHitCode if coarser; with
/// `beyond` (the core's hard limit lies below range_max) reach / (kMaxHitCode - 1), which leaves
/// kMaxHitCode for the readings beyond the limit.
double rangeStep(double reach, bool beyond = false);
/// What a code stands for (m), the same on every side of the stream.
inline float decodeRange(std::uint16_t code, double step) {
  if (code == kInvalidCode) return std::numeric_limits<float>::quiet_NaN();
  if (code == kNoReturnCode) return std::numeric_limits<float>::infinity();
  return static_cast<float>(static_cast<double>(code) * step);
}

class RangeCodec {
 public:
  /// Encodes the ranges of `view` for a map of `params`; true: codes(), step() and decoded() hold
  /// them. False (nothing encoded): no return code fits in [range_min, reach) (a reach or a range
  /// window narrower than a step, never so for a real scanner); the caller sends floats then.
  bool encode(const wavog::ScanView& view, const wavog::MapParams& params);
  /// `view` with its ranges replaced by decoded() (valid while this codec is unchanged).
  wavog::ScanView decodedView(const wavog::ScanView& view) const;

  const std::vector<std::uint16_t>& codes() const { return codes_; }
  double step() const { return step_; }
  const std::vector<float>& decoded() const { return decoded_; }

 private:
  std::vector<std::uint16_t> codes_;
  std::vector<float> decoded_;
  double step_ = kRangeStep;
};

/// Decodes `count` codes at `step` into *out (resized).
void decodeRanges(const std::uint16_t* codes, std::size_t count, double step,
                  std::vector<float>* out);

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_RANGE_CODEC_H_
