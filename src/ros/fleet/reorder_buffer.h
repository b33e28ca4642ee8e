// ReorderBuffer: the fleet node's stamp order over several vehicles' streams, with a bounded wait
// (ROS-free, so it is tested without a master).
//
// Rule: an item is due once it has waited `wait` seconds since its arrival and its stamp is below
// the caller's horizon (a stamp every stream still streaming has delivered past: StreamHorizon), or
// once it has waited `max_wait` seconds whatever the horizon. A due item is integrated together
// with every buffered item that sorts before it, in key order (stamp, vehicle, per-vehicle index).
// So a live stream that lags (a loaded mapper, a slow link) holds the others back instead of
// coming late, for at most `max_wait`; a silent stream holds nothing (the caller leaves it out of
// the horizon), and with no horizon the release is driven by arrival times alone (`wait`). An item
// arriving with a key below the last released one is late: the caller integrates it at once or
// drops it (and counts it). With no late item, the released sequence is the sorted sequence of
// everything pushed, whatever the arrival order: the fleet map is then the map of all scans in
// stamp order. Memory: at most max_items items, and arrival records for the last max_wait
// seconds of pushes (compacted beyond 2 max_items + 64). Not thread-safe (the caller's lock).
#ifndef WAVOG_MAPPING_SRC_ROS_FLEET_REORDER_BUFFER_H_
#define WAVOG_MAPPING_SRC_ROS_FLEET_REORDER_BUFFER_H_

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <iterator>
#include <limits>
#include <map>
#include <set>
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

/// A horizon above every stamp: release by the waits alone.
constexpr std::int64_t kNoHorizon = std::numeric_limits<std::int64_t>::max();

/// What push() did with an item.
enum class Admission {
  kQueued,    ///< waits in the buffer
  kLate,      ///< sorts before an item already released: not queued (the caller decides)
  kOverflow,  ///< the buffer is full: not queued
};

template <typename T>
class ReorderBuffer {
 public:
  /// `wait_s` <= `max_wait_s` (seconds of the clock push() and release() are given).
  ReorderBuffer(double wait_s, double max_wait_s, std::size_t max_items)
      : wait_(wait_s), max_wait_(std::max(wait_s, max_wait_s)), max_(max_items) {}

  /// Offers an item that arrived at `now` (seconds, any monotonic clock).
  Admission push(const OrderKey& key, double now, T item) {
    if (has_released_ && key < last_released_) return Admission::kLate;
    if (items_.size() >= max_) return Admission::kOverflow;
    items_.emplace(key, std::move(item));
    fresh_.push_back({now, key});
    arrivals_.push_back({now, key});
    compact();
    return Admission::kQueued;
  }

  /// Hands every item that is due at `now` to f(key, item), in key order; returns how many.
  /// `horizon_ns`: items stamped below it may go once they have waited `wait`.
  template <typename F>
  std::size_t release(double now, std::int64_t horizon_ns, F&& f) {
    while (!fresh_.empty() && fresh_.front().first + wait_ <= now) {
      if (!has_released_ || last_released_ < fresh_.front().second) {
        waited_.insert(fresh_.front().second);
      }
      fresh_.pop_front();
    }
    while (!arrivals_.empty() && arrivals_.front().first + max_wait_ <= now) {
      raiseDue(arrivals_.front().second);  // waited max_wait: due whatever the horizon
      arrivals_.pop_front();
    }
    // The largest waited key stamped below the horizon.
    const auto above =
        waited_.lower_bound(OrderKey{horizon_ns, std::numeric_limits<int>::min(), 0});
    if (above != waited_.begin()) raiseDue(*std::prev(above));
    if (has_due_) waited_.erase(waited_.begin(), waited_.upper_bound(due_));
    std::size_t n = 0;
    while (has_due_ && !items_.empty() && !(due_ < items_.begin()->first)) {
      n += take(f);
    }
    return n;
  }

  /// release() by the waits alone (no horizon): `wait` after arrival.
  template <typename F>
  std::size_t release(double now, F&& f) {
    return release(now, kNoHorizon, std::forward<F>(f));
  }

  /// Hands every buffered item to f, in key order (the end of the input, a save).
  template <typename F>
  std::size_t releaseAll(F&& f) {
    std::size_t n = 0;
    while (!items_.empty()) n += take(f);
    fresh_.clear();
    arrivals_.clear();
    waited_.clear();
    return n;
  }

  std::size_t size() const { return items_.size(); }
  bool hasReleased() const { return has_released_; }
  const OrderKey& lastReleased() const { return last_released_; }

 private:
  void raiseDue(const OrderKey& key) {
    if (!has_due_ || due_ < key) due_ = key;
    has_due_ = true;
  }

  /// Drops the arrival records of items already released (they hold no memory of their own once
  /// released, but a fast stream pushes many within max_wait).
  void compact() {
    const std::size_t limit = 2 * max_ + 64;
    if (fresh_.size() + arrivals_.size() <= 2 * limit) return;
    const auto released = [this](const std::pair<double, OrderKey>& a) {
      return has_released_ && !(last_released_ < a.second);
    };
    fresh_.erase(std::remove_if(fresh_.begin(), fresh_.end(), released), fresh_.end());
    arrivals_.erase(std::remove_if(arrivals_.begin(), arrivals_.end(), released), arrivals_.end());
  }

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
  double max_wait_;
  std::size_t max_;
  std::multimap<OrderKey, T> items_;
  std::deque<std::pair<double, OrderKey>> fresh_;     ///< not yet waited `wait` (arrival order)
  std::deque<std::pair<double, OrderKey>> arrivals_;  ///< not yet waited `max_wait`
  std::multiset<OrderKey> waited_;  ///< waited `wait`, not yet released: wait for the horizon
  OrderKey due_;                    ///< the largest key that is due
  bool has_due_ = false;
  OrderKey last_released_;
  bool has_released_ = false;
};

}  // namespace wavog_fleet

#endif  // WAVOG_MAPPING_SRC_ROS_FLEET_REORDER_BUFFER_H_
