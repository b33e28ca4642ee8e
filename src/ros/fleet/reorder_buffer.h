// ReorderBuffer: the fleet node's stamp order over several vehicles' streams, with a bounded wait
// and no dependence on any vehicle being alive (ROS-free, so it is tested without a master).
//
// Rule: an item waits at most `wait` seconds after its arrival. When an item's wait is over, it is
// integrated together with every buffered item that sorts before it, in key order (stamp, vehicle,
// per-vehicle index). An item arriving with a key below the last released one is late: the
// caller integrates it at once or drops it (and counts it). A silent vehicle holds nothing up:
// release is driven by arrival times only. With no late item, the released sequence is the sorted
// sequence of everything pushed, whatever the arrival order: the fleet map is then the map of all
// scans in stamp order. Not thread-safe (the caller's lock).
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_REORDER_BUFFER_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_REORDER_BUFFER_H_

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <tuple>
#include <utility>

namespace wavog_fleet {

/// Where a scan sorts in the fleet's order.
struct OrderKey {
  std::int64_t stamp_ns = 0;  ///< the scan's stamp (ns)
  int vehicle = 0;            ///< index of its vehicle in the configuration
  std::uint64_t index = 0;    ///< its index in the vehicle's stream
  bool operator<(const OrderKey& o) const {
    return std::tie(stamp_ns, vehicle, index) < std::tie(o.stamp_ns, o.vehicle, o.index);
  }
};

/// What push() did with an item.
enum class Admission {
  kQueued,    ///< waits in the buffer
  kLate,      ///< sorts before an item already released: not queued (the caller decides)
  kOverflow,  ///< the buffer is full: not queued
};

template <typename T>
class ReorderBuffer {
 public:
  ReorderBuffer(double wait_s, std::size_t max_items) : wait_(wait_s), max_(max_items) {}

  /// Offers an item that arrived at `now` (seconds, any monotonic clock).
  Admission push(const OrderKey& key, double now, T item) {
    if (has_released_ && key < last_released_) return Admission::kLate;
    if (items_.size() >= max_) return Admission::kOverflow;
    items_.emplace(key, std::move(item));
    arrivals_.push_back({now, key});
    return Admission::kQueued;
  }

  /// Hands every item that is due at `now` to f(key, item), in key order; returns how many.
  template <typename F>
  std::size_t release(double now, F&& f) {
    while (!arrivals_.empty() && arrivals_.front().first + wait_ <= now) {
      if (!has_due_ || due_ < arrivals_.front().second) due_ = arrivals_.front().second;
      has_due_ = true;
      arrivals_.pop_front();
    }
    std::size_t n = 0;
    while (has_due_ && !items_.empty() && !(due_ < items_.begin()->first)) {
      n += take(f);
    }
    return n;
  }

  /// Hands every buffered item to f, in key order (the end of the input, a save).
  template <typename F>
  std::size_t releaseAll(F&& f) {
    std::size_t n = 0;
    while (!items_.empty()) n += take(f);
    arrivals_.clear();
    return n;
  }

  std::size_t size() const { return items_.size(); }
  bool hasReleased() const { return has_released_; }
  const OrderKey& lastReleased() const { return last_released_; }

 private:
  template <typename F>
  std::size_t take(F& f) {
    auto it = items_.begin();
    last_released_ = it->first;
    has_released_ = true;
    T item = std::move(it->second);
    const OrderKey key = it->first;
    items_.erase(it);
    f(key, item);
    return 1;
  }

  double wait_;
  std::size_t max_;
  std::multimap<OrderKey, T> items_;
  std::deque<std::pair<double, OrderKey>> arrivals_;  ///< arrival order (= time order)
  OrderKey due_;          ///< the largest key whose wait is over
  bool has_due_ = false;
  OrderKey last_released_;
  bool has_released_ = false;
};

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_REORDER_BUFFER_H_
