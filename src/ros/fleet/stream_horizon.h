// StreamHorizon: how far in stamps every stream still streaming has come (ROS-free, tested
// without a master). A stream is one input of one vehicle (PlacedScan.vehicle's slot and
// PlacedScan.input): a mapper sends each input's scans in stamp order, but interleaves its
// inputs as their transforms come, so only per input is the next stamp known to be no older than
// the last. The horizon is the smallest last stamp over the streams heard from within
// `live_for` seconds: no live stream will send a scan stamped below it (while its stamps keep
// their order), so the fleet's reorder buffer may release every scan below it. A stream silent
// for longer (a stopped vehicle, a dead laser) holds nothing. Bounded: at most
// `max_streams_per_vehicle` streams per vehicle; a new input beyond that replaces the vehicle's
// longest-silent stream if that one is no longer live, and is otherwise not tracked (note()
// returns false: its scans hold nothing and may come late, counted as such by the caller). An input
// is kept as the hash of its name, so a long name costs nothing. Not thread-safe (the caller's
// lock).
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_STREAM_HORIZON_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_STREAM_HORIZON_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "reorder_buffer.h"

namespace wavog_fleet {

class StreamHorizon {
 public:
  /// `vehicles`: the number of vehicle slots; `live_for`: seconds of silence after which a stream
  /// holds nothing (fleet_stale_timeout).
  StreamHorizon(std::size_t vehicles, double live_for, std::size_t max_streams_per_vehicle = 16)
      : vehicles_(vehicles), live_for_(live_for), max_streams_(max_streams_per_vehicle) {}

  /// A scan of `vehicle`'s input `input` stamped `stamp_ns` arrived at `now` (seconds, the clock
  /// horizon() is given). False when the stream is not tracked (see above) or `vehicle` is out
  /// of range.
  bool note(std::size_t vehicle, const std::string& input, std::int64_t stamp_ns, double now) {
    if (vehicle >= vehicles_.size()) return false;
    std::vector<Stream>& streams = vehicles_[vehicle];
    const std::size_t id = std::hash<std::string>{}(input);
    auto it = std::find_if(streams.begin(), streams.end(),
                           [id](const Stream& s) { return s.input == id; });
    if (it == streams.end()) {
      if (streams.size() < max_streams_) {
        streams.push_back({id, stamp_ns, now});
        return true;
      }
      it = std::min_element(streams.begin(), streams.end(), [](const Stream& a, const Stream& b) {
        return a.last_heard < b.last_heard;
      });
      if (live(*it, now)) return false;
      it->input = id;
    }
    it->last_stamp = stamp_ns;  // the last, not the largest: a stream that jumps back holds again
    it->last_heard = now;
    return true;
  }

  /// The smallest last stamp of the streams live at `now`; kNoHorizon when none is.
  std::int64_t horizon(double now) const {
    std::int64_t h = kNoHorizon;
    for (const auto& streams : vehicles_) {
      for (const Stream& s : streams) {
        if (live(s, now)) h = std::min(h, s.last_stamp);
      }
    }
    return h;
  }

  /// Streams tracked for `vehicle` (live or not).
  std::size_t streams(std::size_t vehicle) const {
    return vehicle < vehicles_.size() ? vehicles_[vehicle].size() : 0;
  }

 private:
  struct Stream {
    std::size_t input = 0;  ///< hash of the input's name
    std::int64_t last_stamp = 0;
    double last_heard = 0.0;
  };
  bool live(const Stream& s, double now) const { return now - s.last_heard <= live_for_; }

  std::vector<std::vector<Stream>> vehicles_;
  double live_for_;
  std::size_t max_streams_;
};

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_STREAM_HORIZON_H_
