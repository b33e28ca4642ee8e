// StreamIndex: one vehicle's sequence of PlacedScan.index as the fleet node receives it (ROS-free,
// tested and fuzzed without a master). Every delivered message steps it, whether the fleet node
// then refuses it or not (a refused message was delivered), so `lost` counts exactly the indices
// the stream skipped: messages it never delivered. An index at or below the previous one (a
// duplicate, a restarted mapper) and a forward jump beyond kMaxIndexGap (a corrupt index, another
// stream) are counted on their own, never as lost; the sequence goes on from that index.
// Not thread-safe (the caller's lock).
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_STREAM_INDEX_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_STREAM_INDEX_H_

#include <cstdint>
#include <limits>

namespace wavog_fleet {

/// Largest gap counted as lost (2^32 messages: 310 days of four 40 Hz lasers); a longer forward
/// jump cannot be a real outage and is counted as a jump. One message adds at most this to lost.
constexpr std::uint64_t kMaxIndexGap = std::uint64_t{1} << 32;

/// What one index did to the sequence.
enum class IndexStep {
  kFirst,    ///< the stream's first message
  kNext,     ///< the previous index + 1
  kGap,      ///< further on by at most kMaxIndexGap + 1: the skipped indices were lost
  kRegress,  ///< at or below the previous index (a duplicate, a restarted mapper)
  kJump,     ///< further on by more than kMaxIndexGap + 1 (a corrupt index, another stream)
};

class StreamIndex {
 public:
  /// Steps to `index`; *skipped: the indices it skipped (kGap only, else 0).
  IndexStep step(std::uint64_t index, std::uint64_t* skipped) {
    *skipped = 0;
    const bool first = !has_last_;
    const std::uint64_t last = last_;
    has_last_ = true;
    last_ = index;
    if (first) return IndexStep::kFirst;
    if (index <= last) return IndexStep::kRegress;
    const std::uint64_t ahead = index - last;  // >= 1, no wrap
    if (ahead == 1) return IndexStep::kNext;
    if (ahead - 1 > kMaxIndexGap) return IndexStep::kJump;
    *skipped = ahead - 1;
    return IndexStep::kGap;
  }

 private:
  bool has_last_ = false;
  std::uint64_t last_ = 0;
};

/// a + b, saturated at 2^64 - 1 (a counter never wraps).
inline std::uint64_t saturatingAdd(std::uint64_t a, std::uint64_t b) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  return b > kMax - a ? kMax : a + b;
}

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_STREAM_INDEX_H_
