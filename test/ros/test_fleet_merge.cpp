// The fleet's merge rule without a master (issue 30): the reorder buffer integrates in stamp order
// within its bounded wait whatever the arrival order, counts late and overflowing items, never
// waits for a silent vehicle; foreign PlacedScans are refused by name; and the fleet map (scans of
// three simulated vehicles through PlacedScan, serialisation, arrival out of order, the reorder
// buffer) equals, cell for cell, one map fed all the scans in stamp order, for every policy.
#include <gtest/gtest.h>
#include <ros/serialization.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "fleet/placed_scan.h"
#include "fleet/reorder_buffer.h"
#include "fleet/stream_horizon.h"
#include "map_compare.h"
#include "placed_scan_fixture.h"
#include "wavog_mapping/core/scan_period.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/sim/laser_sim.h"
#include "wavog_mapping/sim/world.h"

namespace {

using wavog_fleet::Admission;
using wavog_fleet::OrderKey;
using wavog_fleet::Refusal;
using wavog_fleet::ReorderBuffer;

OrderKey key(std::int64_t stamp, int vehicle, std::uint64_t index) {
  return OrderKey{stamp, vehicle, index};
}

// ---- the reorder buffer ----------------------------------------------------------------------

TEST(ReorderBuffer, ReleasesInKeyOrderWhateverTheArrivalOrder) {
  std::mt19937 rng(7);
  std::vector<OrderKey> keys;
  for (int v = 0; v < 3; ++v)
    for (std::uint64_t i = 0; i < 200; ++i) keys.push_back(key(static_cast<std::int64_t>(i) * 25, v, i));
  // Each item arrives up to 0.2 s after its stamp (ms units: stamp / 1000 s), in a random order
  // among those; the wait (0.3 s) covers the spread, so nothing is late.
  std::vector<std::pair<double, OrderKey>> arrivals;
  std::uniform_real_distribution<double> delay(0.0, 0.2);
  for (const OrderKey& k : keys) arrivals.push_back({k.stamp_ns / 1000.0 + delay(rng), k});
  std::sort(arrivals.begin(), arrivals.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  ReorderBuffer<int> buffer(0.3, 0.3, 100000);
  std::vector<OrderKey> out;
  auto sink = [&](const OrderKey& k, int) { out.push_back(k); };
  for (const auto& a : arrivals) {
    buffer.release(a.first, sink);
    ASSERT_EQ(buffer.push(a.second, a.first, 0), Admission::kQueued);
  }
  buffer.release(1e9, sink);
  EXPECT_EQ(buffer.size(), 0u);
  std::vector<OrderKey> sorted = keys;
  std::sort(sorted.begin(), sorted.end());
  ASSERT_EQ(out.size(), sorted.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_FALSE(out[i] < sorted[i] || sorted[i] < out[i]) << "position " << i;
  }
}

TEST(ReorderBuffer, HoldsAnItemForTheWaitAndNoLonger) {
  ReorderBuffer<int> buffer(0.5, 0.5, 10);
  int released = 0;
  auto sink = [&](const OrderKey&, int) { ++released; };
  ASSERT_EQ(buffer.push(key(100, 0, 0), 10.0, 0), Admission::kQueued);
  EXPECT_EQ(buffer.release(10.49, sink), 0u);
  EXPECT_EQ(buffer.release(10.5, sink), 1u);
  EXPECT_EQ(released, 1);
}

TEST(ReorderBuffer, ASilentVehicleHoldsNothingUp) {
  // Vehicle 1 never sends again: vehicle 0's items still go out after the wait.
  ReorderBuffer<int> buffer(0.2, 0.2, 10);
  std::vector<OrderKey> out;
  auto sink = [&](const OrderKey& k, int) { out.push_back(k); };
  ASSERT_EQ(buffer.push(key(5, 1, 0), 0.0, 0), Admission::kQueued);
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(buffer.push(key(10 + i, 0, static_cast<std::uint64_t>(i)), 1.0 + i, 0),
              Admission::kQueued);
    buffer.release(1.0 + i + 0.2, sink);
  }
  EXPECT_EQ(out.size(), 6u);
  EXPECT_EQ(buffer.size(), 0u);
}

TEST(ReorderBuffer, AnItemOlderThanTheLastReleasedIsLate) {
  ReorderBuffer<int> buffer(0.1, 0.1, 10);
  auto sink = [](const OrderKey&, int) {};
  ASSERT_EQ(buffer.push(key(100, 0, 0), 0.0, 0), Admission::kQueued);
  ASSERT_EQ(buffer.release(0.2, sink), 1u);
  EXPECT_EQ(buffer.push(key(99, 1, 0), 0.3, 0), Admission::kLate);
  // Same stamp, lower vehicle: it would have gone first, so it is late too.
  EXPECT_EQ(buffer.push(key(100, -1, 0), 0.3, 0), Admission::kLate);
  EXPECT_EQ(buffer.push(key(100, 1, 0), 0.3, 0), Admission::kQueued);
  EXPECT_EQ(buffer.size(), 1u);
}

TEST(ReorderBuffer, RefusesBeyondItsCapacity) {
  ReorderBuffer<int> buffer(1.0, 1.0, 2);
  EXPECT_EQ(buffer.push(key(1, 0, 0), 0.0, 0), Admission::kQueued);
  EXPECT_EQ(buffer.push(key(2, 0, 1), 0.0, 0), Admission::kQueued);
  EXPECT_EQ(buffer.push(key(3, 0, 2), 0.0, 0), Admission::kOverflow);
  std::vector<OrderKey> out;
  EXPECT_EQ(buffer.releaseAll([&](const OrderKey& k, int) { out.push_back(k); }), 2u);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].stamp_ns, 1);
}

// ---- the streams' horizon: a stream that lags but streams holds the others ----------------------

using wavog_fleet::StreamHorizon;

struct Arrival {
  double at;  ///< wall s
  OrderKey key;
  std::string input;
};

struct Replayed {
  std::vector<OrderKey> released;
  std::size_t late = 0;
  std::size_t max_buffered = 0;
};

/// FleetReceiver's path on `arrivals` (sorted by time): note() and push() at each arrival, the
/// release timer every 10 ms; with `horizon` false the release is by arrival times alone (the
/// rule before the horizon). Late items are counted, not released.
Replayed replay(const std::vector<Arrival>& arrivals, double wait, double max_wait, double live_for,
                bool horizon) {
  ReorderBuffer<int> buffer(wait, max_wait, 1000000);
  StreamHorizon streams(4, live_for);
  Replayed run;
  auto sink = [&](const OrderKey& k, int) { run.released.push_back(k); };
  auto releaseAt = [&](double t) {
    buffer.release(t, horizon ? streams.horizon(t) : wavog_fleet::kNoHorizon, sink);
  };
  double tick = 0.0;
  for (const Arrival& a : arrivals) {
    for (; tick <= a.at; tick += 0.01) releaseAt(tick);
    streams.note(static_cast<std::size_t>(a.key.vehicle), a.input, a.key.stamp_ns, a.at);
    if (buffer.push(a.key, a.at, 0) == Admission::kLate) ++run.late;
    run.max_buffered = std::max(run.max_buffered, buffer.size());
  }
  const double end = arrivals.empty() ? 0.0 : arrivals.back().at + max_wait + 0.02;
  for (; tick <= end; tick += 0.01) releaseAt(tick);
  EXPECT_EQ(buffer.size(), 0u) << "everything goes within max_wait of its arrival";
  return run;
}

/// Vehicles with four 40 Hz lasers each (stamps staggered per laser), `seconds` long; each scan
/// arrives 30 ms after its stamp plus its vehicle's lag, which grows by 0.5 s a second up to
/// `lag[vehicle]` s (a loaded mapper's backlog), and per vehicle the lasers' scans are
/// interleaved out of stamp order by up to 20 ms, as a mapper sends them.
std::vector<Arrival> lasers(double seconds, const std::vector<double>& lag) {
  std::vector<Arrival> out;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(0.0, 0.02);
  for (int v = 0; v < static_cast<int>(lag.size()); ++v) {
    std::uint64_t index = 0;
    for (int i = 0; i < static_cast<int>(seconds * 40); ++i) {
      for (int l = 0; l < 4; ++l) {
        const double stamp = 1.0 + i * 0.025 + l * 0.005;
        const OrderKey k{static_cast<std::int64_t>(std::llround(stamp * 1e9)), v, index++};
        const double behind = std::min(lag[static_cast<std::size_t>(v)], 0.5 * (stamp - 1.0));
        out.push_back({stamp + 0.03 + behind + jitter(rng), k, "scan_" + std::to_string(l)});
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const Arrival& a, const Arrival& b) { return a.at < b.at; });
  // A vehicle's index follows its stream order (the order it sent them).
  std::vector<std::uint64_t> next(lag.size(), 0);
  for (Arrival& a : out) a.key.index = next[static_cast<std::size_t>(a.key.vehicle)]++;
  return out;
}

std::vector<OrderKey> sortedKeys(const std::vector<Arrival>& arrivals) {
  std::vector<OrderKey> keys;
  for (const Arrival& a : arrivals) keys.push_back(a.key);
  std::sort(keys.begin(), keys.end());
  return keys;
}

bool sameKeys(const std::vector<OrderKey>& a, const std::vector<OrderKey>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] < b[i] || b[i] < a[i]) return false;
  }
  return true;
}

TEST(ReorderBuffer, AVehicleThatLagsButStreamsHoldsTheOthersInsteadOfComingLate) {
  // fleet.test's failure under load: one vehicle's stream falls 1 s behind the others', more
  // than the wait (0.3 s). By arrival time alone most of its scans are late; with the horizon
  // none is, and the fleet releases every scan in stamp order.
  const std::vector<Arrival> arrivals = lasers(5.0, {0.0, 1.0, 0.0});
  const Replayed before = replay(arrivals, 0.3, 10.0, 2.0, false);
  EXPECT_GT(before.late, arrivals.size() / 6) << "the case the horizon is for";
  const Replayed after = replay(arrivals, 0.3, 10.0, 2.0, true);
  std::printf(
      "a vehicle 1 s behind: %zu of %zu scans late by arrival time alone, %zu with the "
      "horizon\n",
      before.late, arrivals.size(), after.late);
  EXPECT_EQ(after.late, 0u);
  EXPECT_TRUE(sameKeys(after.released, sortedKeys(arrivals)));
  // Memory: the lag's worth of the others' scans (2 vehicles x 160 Hz x 1.3 s), not more.
  EXPECT_LT(after.max_buffered, 3u * 160u * 1.5);
  // The same with the lag on the first vehicle, and growing lags on two of them.
  for (const std::vector<double>& lag :
       {std::vector<double>{2.5, 0.0, 0.0}, std::vector<double>{0.0, 4.0, 7.0}}) {
    const std::vector<Arrival> a = lasers(4.0, lag);
    const Replayed r = replay(a, 0.3, 10.0, 2.0, true);
    EXPECT_EQ(r.late, 0u);
    EXPECT_TRUE(sameKeys(r.released, sortedKeys(a)));
  }
}

TEST(ReorderBuffer, AStreamLaggingBeyondTheMaxWaitHoldsNoLonger) {
  // Vehicle 1's clock runs 20 s behind: it streams, but its stamps never pass the others'.
  // Vehicle 0's scans wait max_wait (2 s) and go; vehicle 1's then come late (counted).
  std::vector<Arrival> arrivals;
  for (int i = 0; i < 200; ++i) {
    const double t = 1.0 + i * 0.025;  // wall s; vehicle 0 stamps t + 100 s, vehicle 1 t + 80 s
    const auto index = static_cast<std::uint64_t>(i);
    arrivals.push_back({t, OrderKey{std::llround((t + 100.0) * 1e9), 0, index}, "a"});
    arrivals.push_back({t + 0.001, OrderKey{std::llround((t + 80.0) * 1e9), 1, index}, "a"});
  }
  ReorderBuffer<int> buffer(0.3, 2.0, 1000000);
  StreamHorizon streams(2, 1.0);
  std::vector<OrderKey> out;
  auto sink = [&](const OrderKey& k, int) { out.push_back(k); };
  std::size_t late = 0;
  for (const Arrival& a : arrivals) {
    buffer.release(a.at, streams.horizon(a.at), sink);
    streams.note(static_cast<std::size_t>(a.key.vehicle), a.input, a.key.stamp_ns, a.at);
    late += buffer.push(a.key, a.at, 0) == Admission::kLate;
  }
  // Vehicle 0's first scan (arrived at 1.0) is held past the wait by vehicle 1's horizon ...
  EXPECT_GT(late, 0u);
  // ... and released at 1.0 + max_wait at the latest: nothing older than that stays.
  buffer.release(1.0 + 2.0, streams.horizon(3.0), sink);
  bool first_out = false;
  for (const OrderKey& k : out) first_out |= k.vehicle == 0 && k.index == 0;
  EXPECT_TRUE(first_out);
  EXPECT_LE(buffer.size(), 2u * 200u);
}

TEST(ReorderBuffer, AStreamSilentForItsLiveTimeHoldsNothing) {
  // Vehicle 1 stops at 2 s (killed); vehicle 0 streams on. Once vehicle 1 has been silent for
  // the live time (0.5 s), vehicle 0's scans go after the wait (0.2 s), as before the horizon.
  ReorderBuffer<int> buffer(0.2, 10.0, 100000);
  StreamHorizon streams(2, 0.5);
  std::vector<OrderKey> out;
  auto sink = [&](const OrderKey& k, int) { out.push_back(k); };
  std::uint64_t i0 = 0, i1 = 0;
  for (double t = 1.0; t < 4.0; t += 0.025) {
    buffer.release(t, streams.horizon(t), sink);
    const std::int64_t ns = std::llround(t * 1e9);
    streams.note(0, "a", ns, t);
    ASSERT_EQ(buffer.push(OrderKey{ns, 0, i0++}, t, 0), Admission::kQueued);
    if (t < 2.0) {
      streams.note(1, "a", ns + 1, t);
      ASSERT_EQ(buffer.push(OrderKey{ns + 1, 1, i1++}, t, 0), Admission::kQueued);
    }
  }
  // At 3.5 s: vehicle 1 silent since ~2.0 s: everything that arrived up to 3.3 s is out.
  buffer.release(3.5, streams.horizon(3.5), sink);
  ASSERT_FALSE(out.empty());
  EXPECT_GE(out.back().stamp_ns, std::llround(3.28 * 1e9));
  // While it streamed, a scan waited for it: none went before the other vehicle passed it.
  EXPECT_TRUE(std::is_sorted(out.begin(), out.end()));
}

TEST(StreamHorizon, TheSmallestLastStampOfTheLiveStreams) {
  StreamHorizon h(3, 1.0, 2);
  EXPECT_EQ(h.horizon(0.0), wavog_fleet::kNoHorizon);  // nothing heard: nothing holds
  ASSERT_TRUE(h.note(0, "front", 100, 0.0));
  ASSERT_TRUE(h.note(0, "rear", 90, 0.0));  // a vehicle's inputs interleave: the least counts
  ASSERT_TRUE(h.note(1, "front", 95, 0.5));
  EXPECT_EQ(h.horizon(0.5), 90);
  ASSERT_TRUE(h.note(0, "rear", 120, 0.6));
  EXPECT_EQ(h.horizon(0.6), 95);
  // Vehicle 0's front is silent for more than 1 s at 1.1 s: its 100 no longer holds.
  ASSERT_TRUE(h.note(1, "front", 130, 1.05));
  EXPECT_EQ(h.horizon(1.1), 120);
  // A stream that jumps back (a restarted bag) holds at its new stamp.
  ASSERT_TRUE(h.note(1, "front", 50, 1.2));
  EXPECT_EQ(h.horizon(1.2), 50);
  // Out of range: not tracked.
  EXPECT_FALSE(h.note(7, "front", 1, 1.2));
  // Once one of a vehicle's two streams is silent (front since 0.0), a third input takes its
  // place; while both are live, a third is not tracked and holds nothing.
  EXPECT_TRUE(h.note(0, "side", 200, 1.3));
  EXPECT_EQ(h.streams(0), 2u);
  EXPECT_FALSE(h.note(0, "top", 1, 1.4));
  EXPECT_EQ(h.horizon(1.4), 50);
  EXPECT_EQ(h.horizon(10.0), wavog_fleet::kNoHorizon);  // all silent
}

// ---- foreign input -----------------------------------------------------------------------------

using placed_scan_fixture::goodScan;

Refusal check(const wavog_mapping::PlacedScan& m) {
  std::string detail;
  const Refusal r =
      wavog_fleet::checkPlacedScan(m, wavog_fleet::PlacedScanLimits{}, ros::Time(100.0), &detail);
  EXPECT_EQ(r == Refusal::kNone, detail.empty()) << detail;
  return r;
}

TEST(PlacedScanCheck, RefusesForeignInputByName) {
  EXPECT_EQ(check(goodScan()), Refusal::kNone);
  auto m = goodScan();
  m.version = 3;  // a future writer
  EXPECT_EQ(check(m), Refusal::kVersion);
  m.version = 0;
  EXPECT_EQ(check(m), Refusal::kVersion);
  m = goodScan();
  m.header.frame_id = "odom";
  EXPECT_EQ(check(m), Refusal::kFrame);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m = goodScan();
  m.x = nan;
  EXPECT_EQ(check(m), Refusal::kBadPose);
  m = goodScan();
  m.theta = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check(m), Refusal::kBadPose);
  m = goodScan();
  m.angle_increment = 0.0;  // scan geometry, as the core's bad_geometry
  EXPECT_EQ(check(m), Refusal::kBadSize);
  m = goodScan();
  m.angle_increment = 1e-310;  // denormal
  EXPECT_EQ(check(m), Refusal::kBadSize);
  m = goodScan();
  m.header.stamp = ros::Time();
  EXPECT_EQ(check(m), Refusal::kBadStamp);
  for (const double bad : {nan, std::numeric_limits<double>::infinity(), 1e30}) {
    for (int field = 0; field < 6; ++field) {
      for (const bool compensated : {false, true}) {
        m = goodScan();
        m.compensated = compensated;
        double* f[] = {&m.start_x, &m.start_y, &m.start_theta, &m.end_x, &m.end_y, &m.end_theta};
        *f[field] = bad;
        EXPECT_EQ(check(m), Refusal::kBadPose) << "field " << field << " = " << bad;
      }
    }
  }
  m = goodScan();
  m.theta = 1e30;
  EXPECT_EQ(check(m), Refusal::kBadPose);
  m = goodScan();
  m.x = 1e8;  // beyond 2^30 cells of 5 cm
  EXPECT_EQ(check(m), Refusal::kBadPose);
  m = goodScan();
  m.ranges.clear();
  EXPECT_EQ(check(m), Refusal::kBadSize);
  m = goodScan();
  m.angle_increment = 0.1;  // 181 beams over 18 rad: more than a turn
  EXPECT_EQ(check(m), Refusal::kBadSize);
  m = goodScan();
  m.range_max = 0.05;  // below range_min
  EXPECT_EQ(check(m), Refusal::kBadSize);
  EXPECT_STREQ(wavog_fleet::toString(Refusal::kVersion), "version");
}

// A mapper's period comes from wavog::ScanPeriod: 0 (unknown) or in (0, kMaxPeriod]. Any other
// one is foreign: under forget_half_life a period of 1e300 would forget, in one scan, every cell
// its fan observes.
TEST(PlacedScanCheck, RefusesAPeriodNoMapperSendsAsBadSize) {
  const double inf = std::numeric_limits<double>::infinity();
  for (const double good : {0.0, -0.0, 1e-9, 0.025, wavog::ScanPeriod::kMaxPeriod}) {
    auto m = goodScan();
    m.period = good;
    EXPECT_EQ(check(m), Refusal::kNone) << "period " << good;
  }
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), inf, -inf, -0.025,
                           -std::numeric_limits<double>::denorm_min(),
                           std::nextafter(wavog::ScanPeriod::kMaxPeriod, inf), 1e300}) {
    auto m = goodScan();
    m.period = bad;
    EXPECT_EQ(check(m), Refusal::kBadSize) << "period " << bad;
  }
  wavog::MapParams params = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  params.policy.forget_half_life = 10.0;
  const wavog::WaveletMap map(params);
  // What the check keeps from the fleet map: the core's full forgetting (every value negligible).
  EXPECT_GT(map.forgetRate(1e300), 1.0 - 1e-6);
  EXPECT_LT(map.forgetRate(wavog::ScanPeriod::kMaxPeriod), 0.07) << "a mapper's longest";
}

// ---- the merge rule ------------------------------------------------------------------------------

struct Placed {
  OrderKey key;
  wavog_mapping::PlacedScan msg;  ///< as received (serialised and back)
};

/// The map parameters of the merge tests' vehicles (`type`'s defaults, 10 cm).
wavog::MapParams mergeParams(wavog::PolicyType type) {
  wavog::MapParams params = wavog::MapParams::defaultsFor(type);
  params.grid.resolution = 0.1;
  return params;
}

/// Every scan of `vehicles` vehicles of a short car-park run, as their mappers would stream them:
/// with `codes`, as 16-bit codes (PlacedScan version 2, as FleetStream::streamView() encodes them
/// for a map of mergeParams()), else as float32 (version 1).
std::vector<Placed> fleetScans(int vehicles, double duration, bool codes = false) {
  std::vector<Placed> out;
  const wavog::sim::World base = wavog::sim::defaultWorld(duration);
  for (int k = 0; k < vehicles; ++k) {
    const wavog::sim::World w = wavog::sim::fleetMember(base, k, vehicles);
    wavog::sim::ScanSimulator sim(w, 11 + static_cast<std::uint64_t>(k));
    wavog::sim::SimScan s;
    std::uint64_t index = 0;
    wavog_fleet::RangeCodec codec;
    while (sim.next(&s)) {
      const auto& laser = w.vehicle.lasers[static_cast<std::size_t>(s.laser)];
      wavog::ScanView view = s.view(laser);
      view.period = 1.0 / laser.rate_hz;
      wavog_mapping::PlacedScan m;
      const ros::Time stamp(1000.0 + s.stamp);
      const bool encoded =
          codes && codec.encode(view, mergeParams(wavog::PolicyType::kForget));
      EXPECT_EQ(encoded, codes);
      wavog_fleet::fillPlacedScan(stamp, "map", "v" + std::to_string(k), laser.topic, index,
                                  s.sensor_pose, view, false, s.sensor_pose, s.sensor_pose, &m,
                                  encoded ? &codec : nullptr);
      // Through the wire format.
      const std::uint32_t n = ros::serialization::serializationLength(m);
      std::vector<std::uint8_t> bytes(n);
      ros::serialization::OStream os(bytes.data(), n);
      ros::serialization::serialize(os, m);
      Placed p;
      ros::serialization::IStream is(bytes.data(), n);
      ros::serialization::deserialize(is, p.msg);
      p.key = OrderKey{static_cast<std::int64_t>(stamp.toNSec()), k, index++};
      out.push_back(std::move(p));
    }
  }
  return out;
}

void expectSameCells(const wavog::WaveletMap& a, const wavog::WaveletMap& b, const char* what) {
  wavog::CellBox ba, bb;
  ASSERT_TRUE(a.bounds(0, &ba)) << what;
  ASSERT_TRUE(b.bounds(0, &bb)) << what;
  ASSERT_TRUE(ba.min_x == bb.min_x && ba.min_y == bb.min_y && ba.max_x == bb.max_x &&
              ba.max_y == bb.max_y)
      << what;
  const wavog::Raster ra = a.exportScale(0, ba, wavog::Aggregation::kMean);
  const wavog::Raster rb = b.exportScale(0, bb, wavog::Aggregation::kMean);
  ASSERT_EQ(ra.log_odds.size(), rb.log_odds.size());
  const std::size_t differ = map_compare::differingCells(ra, rb);
  const std::size_t known = map_compare::knownCells(ra);
  EXPECT_EQ(differ, 0u) << what << ": cells that differ of " << ra.log_odds.size();
  EXPECT_GT(known, 10000u) << what;  // a real map, not two empty ones
}

/// The merge rule for every policy, the streams as 16-bit codes or as float32.
void expectMergeRuleForEveryPolicy(bool codes) {
  const std::vector<Placed> scans = fleetScans(3, 2.0, codes);
  ASSERT_GT(scans.size(), 900u);
  std::vector<float> decoded;  // a version-2 scan's ranges (as FleetReceiver)
  // Arrival: each scan up to 0.25 s after its stamp, vehicles interleaved at random.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> delay(0.0, 0.25);
  std::vector<std::pair<double, std::size_t>> arrivals;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    arrivals.push_back({scans[i].msg.header.stamp.toSec() + delay(rng), i});
  }
  std::sort(arrivals.begin(), arrivals.end());
  std::vector<std::size_t> stamp_order(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) stamp_order[i] = i;
  std::sort(stamp_order.begin(), stamp_order.end(),
            [&](std::size_t a, std::size_t b) { return scans[a].key < scans[b].key; });

  using wavog::PolicyType;
  struct Case {
    PolicyType type;
    double half_life;
  };
  for (const Case c : {Case{PolicyType::kNone, 0}, Case{PolicyType::kMax, 0},
                       Case{PolicyType::kClamp, 0}, Case{PolicyType::kForget, 0},
                       Case{PolicyType::kForget, 0.5}, Case{PolicyType::kClampLower, 0},
                       Case{PolicyType::kClampUpper, 0}}) {
    wavog::MapParams params = mergeParams(c.type);
    params.policy.forget_half_life = c.half_life;
    const std::string what = std::string(wavog::toString(c.type)) +
                             (c.half_life > 0 ? " (forget_half_life)" : "");

    // The fleet node's path: checks, the reorder buffer, the decoded core call.
    wavog::WaveletMap fleet(params);
    ReorderBuffer<std::size_t> buffer(0.3, 0.3, 100000);
    std::size_t integrated = 0;
    auto integrate = [&](const OrderKey&, std::size_t i) {
      const auto& m = scans[i].msg;
      ASSERT_EQ(wavog_fleet::checkPlacedScan(m, wavog_fleet::PlacedScanLimits{},
                                             m.header.stamp, nullptr),
                Refusal::kNone);
      const wavog::IntegrateStats st =
          fleet.integrate(wavog_fleet::placedPose(m), wavog_fleet::placedView(m, &decoded));
      integrated += st.status == wavog::ScanStatus::kOk;
    };
    for (const auto& a : arrivals) {
      buffer.release(a.first, integrate);
      ASSERT_EQ(buffer.push(scans[a.second].key, a.first, a.second), Admission::kQueued) << what;
    }
    buffer.releaseAll(integrate);
    EXPECT_EQ(integrated, scans.size()) << what;

    // One mapper fed every scan in stamp order.
    wavog::WaveletMap single(params);
    for (std::size_t i : stamp_order) {
      const auto& m = scans[i].msg;
      single.integrate(wavog_fleet::placedPose(m), wavog_fleet::placedView(m, &decoded));
    }
    expectSameCells(fleet, single, what.c_str());
  }
}

TEST(FleetMerge, FleetMapEqualsOneMapOfAllScansInStampOrderForEveryPolicy) {
  expectMergeRuleForEveryPolicy(true);  // the default stream (fleet_stream_format: uint16)
}

TEST(FleetMerge, FleetMapEqualsOneMapOfAllScansInStampOrderFloatStream) {
  expectMergeRuleForEveryPolicy(false);  // fleet_stream_format: float32
}

TEST(FleetMerge, VehicleMapEqualsFleetMapOfItsCodedStream) {
  // A mapper streaming 16-bit codes integrates the decoded ranges (FleetStream::streamView()); a
  // fleet node integrates the codes it receives, decoded: the same floats, the same map. And the
  // codes are not the floats: without them the maps would differ, so the test is not vacuous.
  const wavog::MapParams params = mergeParams(wavog::PolicyType::kForget);
  const wavog::sim::World w = wavog::sim::defaultWorld(2.0);
  wavog::sim::ScanSimulator sim(w, 11);
  wavog::sim::SimScan s;
  wavog::WaveletMap vehicle(params), fleet(params), unquantised(params);
  wavog_fleet::RangeCodec codec;
  std::vector<float> decoded;
  std::size_t scans = 0, changed_ranges = 0;
  while (sim.next(&s)) {
    const auto& laser = w.vehicle.lasers[static_cast<std::size_t>(s.laser)];
    wavog::ScanView view = s.view(laser);
    view.period = 1.0 / laser.rate_hz;
    ASSERT_TRUE(codec.encode(view, params));
    const wavog::ScanView integrated = codec.decodedView(view);
    for (std::size_t j = 0; j < view.count; ++j) {
      changed_ranges += std::memcmp(&view.ranges[j], &integrated.ranges[j], sizeof(float)) != 0;
    }
    ASSERT_EQ(vehicle.integrate(s.sensor_pose, integrated).status, wavog::ScanStatus::kOk);
    unquantised.integrate(s.sensor_pose, view);
    wavog_mapping::PlacedScan m;
    wavog_fleet::fillPlacedScan(ros::Time(1000.0 + s.stamp), "map", "v1", laser.topic, scans++,
                                s.sensor_pose, integrated, false, s.sensor_pose, s.sensor_pose, &m,
                                &codec);
    ASSERT_EQ(m.version, wavog_mapping::PlacedScan::VERSION_UINT16);
    ASSERT_TRUE(m.ranges.empty());
    // Through the wire format.
    const std::uint32_t n = ros::serialization::serializationLength(m);
    std::vector<std::uint8_t> bytes(n);
    ros::serialization::OStream os(bytes.data(), n);
    ros::serialization::serialize(os, m);
    wavog_mapping::PlacedScan got;
    ros::serialization::IStream is(bytes.data(), n);
    ros::serialization::deserialize(is, got);
    ASSERT_EQ(wavog_fleet::checkPlacedScan(got, wavog_fleet::PlacedScanLimits{},
                                           got.header.stamp, nullptr),
              Refusal::kNone);
    ASSERT_EQ(fleet.integrate(wavog_fleet::placedPose(got), wavog_fleet::placedView(got, &decoded))
                  .status,
              wavog::ScanStatus::kOk);
  }
  ASSERT_GT(scans, 300u);
  EXPECT_GT(changed_ranges, scans * 100);  // most returns moved by up to half a millimetre
  expectSameCells(vehicle, fleet, "vehicle and fleet");
  std::size_t differ = 0, known = 0;
  wavog::CellBox box;
  ASSERT_TRUE(vehicle.bounds(0, &box));
  const wavog::Raster a = vehicle.exportScale(0, box, wavog::Aggregation::kMean);
  const wavog::Raster b = unquantised.exportScale(0, box, wavog::Aggregation::kMean);
  for (std::size_t i = 0; i < a.log_odds.size(); ++i) {
    known += a.known[i];
    differ += std::memcmp(&a.log_odds[i], &b.log_odds[i], sizeof(float)) != 0;
  }
  EXPECT_GT(differ, 0u);
  std::printf("vehicle map of the codes vs of the floats: %zu of %zu known cells differ\n",
              differ, known);
}

TEST(FleetMerge, OrderMattersUnderForgettingSoTheRuleIsNotVacuous) {
  // The same scans in arrival order without the buffer: under "forget" the map differs.
  const std::vector<Placed> scans = fleetScans(3, 1.0);
  std::vector<std::size_t> by_vehicle(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) by_vehicle[i] = i;  // vehicle 0's first, ...
  std::vector<std::size_t> by_stamp = by_vehicle;
  std::sort(by_stamp.begin(), by_stamp.end(),
            [&](std::size_t a, std::size_t b) { return scans[a].key < scans[b].key; });
  const wavog::MapParams params = mergeParams(wavog::PolicyType::kForget);
  wavog::WaveletMap a(params), b(params);
  std::vector<float> decoded;
  for (std::size_t i : by_vehicle) {
    a.integrate(wavog_fleet::placedPose(scans[i].msg),
                wavog_fleet::placedView(scans[i].msg, &decoded));
  }
  for (std::size_t i : by_stamp) {
    b.integrate(wavog_fleet::placedPose(scans[i].msg),
                wavog_fleet::placedView(scans[i].msg, &decoded));
  }
  wavog::CellBox box;
  ASSERT_TRUE(b.bounds(0, &box));
  const wavog::Raster ra = a.exportScale(0, box, wavog::Aggregation::kMean);
  const wavog::Raster rb = b.exportScale(0, box, wavog::Aggregation::kMean);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < ra.log_odds.size(); ++i) differ += ra.log_odds[i] != rb.log_odds[i];
  EXPECT_GT(differ, 100u);
}

}  // namespace
