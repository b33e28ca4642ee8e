// libFuzzer harness: the fleet node's message path without a roscore, on PlacedScan messages with
// every field mutated, from up to three vehicles, at a hostile fleet clock: the node's own intake
// (intake.h: received, the index sequence, checkPlacedScan, the refusal counters), then the
// reorder buffer with the streams' horizon and the core call as FleetReceiver composes them (late
// scans integrated or dropped, overflow), and the stamp arithmetic it does on what passed.
// Oracles: nothing throws, no undefined behaviour; per vehicle the counters add up (every received
// message is refused by one reason, overflows, is late or is integrated / refused by the core) and
// `lost`, index_regressions and index_jumps equal an independent 128-bit count of the index
// sequence; a message that passed the checks is one the core takes without refusing its
// geometry, at a stamp ros::Time arithmetic can handle, with a period a mapper sends ([0,
// ScanPeriod::kMaxPeriod]), and one refused as bad size has an absurd period or is one the core
// refuses as bad geometry (or empty); the buffer releases in key order; the map stays finite at
// every scale.
#include <ros/time.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fleet/intake.h"
#include "fleet/placed_scan.h"
#include "fleet/reorder_buffer.h"
#include "fleet/stream_horizon.h"
#include "fleet/stream_index.h"
#include "fuzz_support.h"
#include "wavog_mapping/PlacedScan.h"
#include "wavog_mapping/VehicleStatus.h"
#include "wavog_mapping/core/scan_period.h"
#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/conversions.h"

namespace {

using wavog_fuzz::hostileDouble;
using wavog_fuzz::hostileNsec;
using wavog_fuzz::hostileRange;
using wavog_fuzz::hostileSec;
using Msg = std::shared_ptr<const wavog_mapping::PlacedScan>;

constexpr std::size_t kMaxMessages = 8;
constexpr std::size_t kMaxBeams = 180;
const char* const kFrames[] = {"map", "", "/map", "odom"};

struct Vehicle {
  wavog_mapping::VehicleStatus c;
  wavog_fleet::StreamIndex index;
  std::uint64_t queued = 0;    // pushed into the buffer
  std::uint64_t released = 0;  // taken out of it and handed to the core
  // The independent count of the index sequence (128-bit arithmetic).
  bool has_last = false;
  std::uint64_t last = 0;
  unsigned __int128 lost = 0;
  std::uint64_t regressions = 0, jumps = 0;
};

// A stamp near the fleet clock (most messages pass the stamp check) or a hostile one.
ros::Time decodeStamp(FuzzedDataProvider* in, const ros::Time& now) {
  ros::Time t;
  if (in->ConsumeBool()) {
    if (wavog_ros::addSeconds(now, hostileDouble(in, -2.0, 2.0), &t)) return t;
  }
  t.sec = hostileSec(in);
  t.nsec = hostileNsec(in);
  return t;
}

std::uint64_t decodeIndex(FuzzedDataProvider* in, const Vehicle& v) {
  const std::uint64_t last = v.last;
  switch (in->ConsumeIntegralInRange<int>(0, 6)) {
    case 0:
    case 1:
      return last + 1;  // the usual case (wraps after 2^64 - 1: a regression)
    case 2:
      return last + in->ConsumeIntegralInRange<std::uint64_t>(2, 1000);  // a gap
    case 3:
      return last;  // a duplicate
    case 4:
      return ~std::uint64_t{0};
    case 5:
      return last + wavog_fleet::kMaxIndexGap + in->ConsumeIntegralInRange<std::uint64_t>(0, 2);
    default:
      return in->ConsumeIntegral<std::uint64_t>();
  }
}

Msg decodeMessage(FuzzedDataProvider* in, const ros::Time& now, const Vehicle& v) {
  auto m = std::make_shared<wavog_mapping::PlacedScan>();
  switch (in->ConsumeIntegralInRange<int>(0, 2)) {
    case 0:
      m->version = wavog_mapping::PlacedScan::VERSION_FLOAT32;
      break;
    case 1:
      m->version = wavog_mapping::PlacedScan::VERSION_UINT16;
      break;
    default:
      m->version = in->ConsumeIntegral<std::uint8_t>();
  }
  m->header.frame_id = kFrames[in->ConsumeIntegralInRange<std::size_t>(0, std::size(kFrames) - 1)];
  m->header.stamp = decodeStamp(in, now);
  m->header.seq = in->ConsumeIntegral<std::uint32_t>();
  m->vehicle = in->ConsumeRandomLengthString(16);
  m->input = in->ConsumeRandomLengthString(16);
  m->index = decodeIndex(in, v);
  m->x = hostileDouble(in, -20.0, 20.0);
  m->y = hostileDouble(in, -20.0, 20.0);
  m->theta = hostileDouble(in, -3.2, 3.2);
  m->compensated = in->ConsumeBool();
  if (in->ConsumeBool()) {
    m->start_x = m->end_x = m->x;
    m->start_y = m->end_y = m->y;
    m->start_theta = m->end_theta = m->theta;
  } else {
    m->start_x = hostileDouble(in, -20.0, 20.0);
    m->start_y = hostileDouble(in, -20.0, 20.0);
    m->start_theta = hostileDouble(in, -3.2, 3.2);
    m->end_x = hostileDouble(in, -20.0, 20.0);
    m->end_y = hostileDouble(in, -20.0, 20.0);
    m->end_theta = hostileDouble(in, -3.2, 3.2);
  }
  m->angle_min = hostileDouble(in, -3.2, 3.2);
  m->angle_increment = hostileDouble(in, -0.1, 0.1);
  m->range_min = hostileDouble(in, 0.0, 1.0);
  m->range_max = hostileDouble(in, 0.0, 30.0);
  m->period = hostileDouble(in, 0.0, 1.0);
  // The ranges in the array of the version, mostly; sometimes in the other one or in both.
  const int arrays = in->ConsumeIntegralInRange<int>(0, 3);  // 0, 1: its own; 2: the other; 3
  const bool codes = m->version == wavog_mapping::PlacedScan::VERSION_UINT16;
  const bool own = arrays <= 1;
  if ((own && !codes) || (arrays == 2 && codes) || arrays == 3) {
    m->ranges.resize(in->ConsumeIntegralInRange<std::size_t>(0, kMaxBeams));
    for (float& r : m->ranges) r = hostileRange(in, 30.0f);
  }
  if ((own && codes) || (arrays == 2 && !codes) || arrays == 3) {
    m->range_codes.resize(in->ConsumeIntegralInRange<std::size_t>(0, kMaxBeams));
    for (std::uint16_t& c : m->range_codes) c = in->ConsumeIntegral<std::uint16_t>();
    m->range_step = in->ConsumeBool() ? wavog_fleet::kRangeStep : hostileDouble(in, 0.0, 0.01);
  }
  return m;
}

// The independent count of one delivered index.
void countIndex(Vehicle* v, std::uint64_t index) {
  if (v->has_last) {
    if (index <= v->last) {
      ++v->regressions;
    } else {
      const unsigned __int128 skipped = static_cast<unsigned __int128>(index) - v->last - 1;
      if (skipped > wavog_fleet::kMaxIndexGap) {
        ++v->jumps;
      } else {
        v->lost += skipped;
      }
    }
  }
  v->has_last = true;
  v->last = index;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  wavog::MapParams params = wavog::MapParams::defaultsFor(static_cast<wavog::PolicyType>(
      in.ConsumeIntegralInRange<int>(0, 5)));
  params.grid.resolution = in.ConsumeBool() ? 0.1 : 0.05;
  params.grid.block_levels = in.ConsumeIntegralInRange<int>(3, 6);
  if (params.policy.type == wavog::PolicyType::kForget && in.ConsumeBool()) {
    params.policy.forget_half_life = in.ConsumeFloatingPointInRange<double>(0.1, 100.0);
  }
  wavog::WaveletMap map(params);

  wavog_fleet::PlacedScanLimits limits;
  limits.resolution = params.grid.resolution;
  limits.max_stamp_offset = in.ConsumeBool() ? 60.0 : in.ConsumeFloatingPointInRange<double>(1e-3, 86400.0);
  const bool integrate_late = in.ConsumeBool();
  const double wait = in.ConsumeFloatingPointInRange<double>(0.0, 1.0);
  const double max_wait = wait + in.ConsumeFloatingPointInRange<double>(0.0, 2.0);
  wavog_fleet::ReorderBuffer<Msg> buffer(wait, max_wait,
                                         in.ConsumeIntegralInRange<std::size_t>(1, 4));
  std::vector<Vehicle> vehicles(in.ConsumeIntegralInRange<std::size_t>(1, 3));
  // As FleetReceiver: the streams' progress (live for fleet_stale_timeout) bounds the release.
  wavog_fleet::StreamHorizon horizon(vehicles.size(),
                                     in.ConsumeFloatingPointInRange<double>(0.01, 2.0),
                                     in.ConsumeIntegralInRange<std::size_t>(1, 3));

  // The fleet clock (ros::Time::now(): normalised) and the wall clock of the arrivals.
  ros::Time now;
  now.sec = hostileSec(&in);
  now.nsec = in.ConsumeIntegralInRange<std::uint32_t>(0, 999999999u);
  double wall = 0.0;

  std::vector<float> decoded;  // a version-2 message's ranges (as FleetReceiver)
  const auto integrate = [&](Vehicle* v, const wavog_mapping::PlacedScan& m) {
    const wavog::IntegrateStats st =
        map.integrate(wavog_fleet::placedPose(m), wavog_fleet::placedView(m, &decoded));
    // The checks refuse every scan and pose the core would refuse as such.
    WAVOG_FUZZ_CHECK(st.status != wavog::ScanStatus::kBadGeometry &&
                         st.status != wavog::ScanStatus::kBadPose &&
                         st.status != wavog::ScanStatus::kEmpty,
                     "a message that passed checkPlacedScan: %s to the core",
                     wavog::toString(st.status));
    if (st.status != wavog::ScanStatus::kOk) {
      ++v->c.dropped_refused;
      return;
    }
    ++v->c.integrated;
    const double lag = wavog_ros::secondsBetween(now, m.header.stamp);  // as integrateLocked
    WAVOG_FUZZ_CHECK(std::isfinite(lag), "lag %g", lag);
  };
  wavog_fleet::OrderKey last_key;
  bool has_last_key = false;
  const auto release = [&](const wavog_fleet::OrderKey& key, const Msg& m) {
    // The buffer releases in key order, whatever the horizon did.
    WAVOG_FUZZ_CHECK(!has_last_key || !(key < last_key), "released out of key order");
    last_key = key;
    has_last_key = true;
    Vehicle& v = vehicles[static_cast<std::size_t>(key.vehicle)];
    ++v.released;
    integrate(&v, *m);
  };

  try {
    const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(1, kMaxMessages);
    for (std::size_t i = 0; i < n && in.remaining_bytes() > 0; ++i) {
      const auto vi = in.ConsumeIntegralInRange<std::size_t>(0, vehicles.size() - 1);
      Vehicle& v = vehicles[vi];
      const Msg m = decodeMessage(&in, now, v);
      wall += in.ConsumeFloatingPointInRange<double>(0.0, 1.0);
      ros::Time later;
      if (wavog_ros::addSeconds(now, in.ConsumeFloatingPointInRange<double>(0.0, 1.0), &later)) {
        now = later;
      }
      countIndex(&v, m->index);
      const wavog_fleet::Intake got = wavog_fleet::takeIn(*m, limits, now, &v.index, &v.c);
      WAVOG_FUZZ_CHECK(got.refusal == wavog_fleet::Refusal::kNone || !got.detail.empty(),
                       "refusal %s without a detail", wavog_fleet::toString(got.refusal));
      const bool period_ok =
          m->period >= 0.0 && m->period <= wavog::ScanPeriod::kMaxPeriod;  // a mapper's
      // Ranges as a mapper of either version sends them: only its array, a step it may use.
      const bool arrays_ok =
          m->version == wavog_mapping::PlacedScan::VERSION_UINT16
              ? m->ranges.empty() && m->range_step >= wavog_fleet::kRangeStep &&
                    m->range_step <= wavog_fleet::kMaxRangeStep
              : m->range_codes.empty();
      if (got.refusal == wavog_fleet::Refusal::kBadSize && period_ok && arrays_ok) {
        // The converse: what the checks call bad size, the core refuses as such (a mapper's
        // message is never refused for a scan its core integrated); or its period is absurd.
        wavog::WaveletMap scratch(params);
        const wavog::ScanStatus st =
            scratch.integrate(wavog_fleet::placedPose(*m), wavog_fleet::placedView(*m, &decoded))
                .status;
        WAVOG_FUZZ_CHECK(st == wavog::ScanStatus::kBadGeometry || st == wavog::ScanStatus::kEmpty,
                         "bad_size to the fleet, %s to the core: %s", wavog::toString(st),
                         got.detail.c_str());
      }
      if (got.refusal == wavog_fleet::Refusal::kNone) {
        // What FleetReceiver computes on a message that passed: fits ros::Time arithmetic.
        const double offset = wavog_ros::secondsBetween(m->header.stamp, now);
        WAVOG_FUZZ_CHECK(std::isfinite(offset) && std::fabs(offset) <= limits.max_stamp_offset &&
                             m->header.stamp.nsec < 1000000000u && !m->header.stamp.isZero(),
                         "stamp %u.%u passed, %g s from the clock", m->header.stamp.sec,
                         m->header.stamp.nsec, offset);
        (void)(m->header.stamp - now);  // may throw beyond 2^31 s: not after the check
        WAVOG_FUZZ_CHECK(period_ok, "period %g passed", m->period);
        v.c.last_stamp = m->header.stamp;
        const wavog_fleet::OrderKey key{static_cast<std::int64_t>(m->header.stamp.toNSec()),
                                        static_cast<int>(vi), m->index};
        horizon.note(vi, m->input, key.stamp_ns, wall);
        switch (buffer.push(key, wall, m)) {
          case wavog_fleet::Admission::kQueued:
            ++v.queued;
            break;
          case wavog_fleet::Admission::kOverflow:
            ++v.c.dropped_overflow;
            break;
          case wavog_fleet::Admission::kLate:
            if (integrate_late) {
              ++v.c.integrated_late;
              integrate(&v, *m);
            } else {
              ++v.c.dropped_late;
            }
            break;
        }
      }
      buffer.release(wall, horizon.horizon(wall), release);
    }
    buffer.releaseAll(release);
  } catch (const std::exception& e) {
    WAVOG_FUZZ_CHECK(false, "the fleet path threw: %s", e.what());
  }

  for (const Vehicle& v : vehicles) {
    const wavog_mapping::VehicleStatus& c = v.c;
    const std::uint64_t refused = c.dropped_version + c.dropped_frame + c.dropped_bad_stamp +
                                  c.dropped_bad_pose + c.dropped_bad_size + c.dropped_bad_length;
    WAVOG_FUZZ_CHECK(c.received == refused + v.queued + c.dropped_overflow + c.dropped_late +
                                       c.integrated_late,
                     "received %llu: refused %llu, queued %llu, overflow %llu, late %llu + %llu",
                     static_cast<unsigned long long>(c.received),
                     static_cast<unsigned long long>(refused),
                     static_cast<unsigned long long>(v.queued),
                     static_cast<unsigned long long>(c.dropped_overflow),
                     static_cast<unsigned long long>(c.dropped_late),
                     static_cast<unsigned long long>(c.integrated_late));
    WAVOG_FUZZ_CHECK(v.released == v.queued && c.integrated + c.dropped_refused ==
                                                   v.released + c.integrated_late,
                     "released %llu of %llu queued; integrated %llu, refused by the core %llu",
                     static_cast<unsigned long long>(v.released),
                     static_cast<unsigned long long>(v.queued),
                     static_cast<unsigned long long>(c.integrated),
                     static_cast<unsigned long long>(c.dropped_refused));
    WAVOG_FUZZ_CHECK(c.lost == v.lost && c.index_regressions == v.regressions &&
                         c.index_jumps == v.jumps,
                     "lost %llu, regressions %llu, jumps %llu; counted %llu, %llu, %llu",
                     static_cast<unsigned long long>(c.lost),
                     static_cast<unsigned long long>(c.index_regressions),
                     static_cast<unsigned long long>(c.index_jumps),
                     static_cast<unsigned long long>(v.lost),
                     static_cast<unsigned long long>(v.regressions),
                     static_cast<unsigned long long>(v.jumps));
  }
  (void)wavog_fuzz::readOutEveryScale(map);  // finite everywhere it reads
  return 0;
}
