#include "wavog_mapping/sim/evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace wavog {
namespace sim {
namespace {

constexpr double kFootprintStep = 0.01;  // time step when looking for a vacated footprint (s)
constexpr int kMinHits = 2;              // true hits that make a cell part of an event
// Log-odds margin around 0 (P = 0.5) for "occupied" and "free": a cell the map holds at exactly
// the unknown value (e.g. max policy, seen free) may read back as +-1e-7 after the Haar round trip.
constexpr float kDecisionMargin = 1e-3f;

// True if the centre of `cell` lies on a beam of `scan` at least one cell before its true hit:
// the lasers saw it free.
bool seenFree(const SimScan& scan, const LaserParams& l, const CellIndex& cell, double res) {
  const double cx = (static_cast<double>(cell.x) + 0.5) * res - scan.sensor_pose.x;
  const double cy = (static_cast<double>(cell.y) + 0.5) * res - scan.sensor_pose.y;
  const double rel = wrapAngle(std::atan2(cy, cx) - scan.sensor_pose.theta - l.angleMin());
  const double beam = std::round(rel / l.angleIncrement());
  if (beam < 0 || beam >= l.beams) return false;
  return scan.true_ranges[static_cast<std::size_t>(beam)] > std::hypot(cx, cy) + res;
}

// Time at which a departing object starts to move: the end of its first constant stretch.
double departureStart(const WorldObject& o) {
  const std::vector<Waypoint>& w = o.trajectory.waypoints;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const Pose2& a = w[0].pose;
    const Pose2& b = w[i].pose;
    if (a.x != b.x || a.y != b.y || a.theta != b.theta) return w[i - 1].t;
  }
  return o.disappear_time;
}

// 3x3 dilation of a mask.
std::vector<std::uint8_t> dilate(const std::vector<std::uint8_t>& mask, const GridWindow& w) {
  std::vector<std::uint8_t> out(mask.size(), 0);
  for (int r = 0; r < w.height; ++r) {
    for (int c = 0; c < w.width; ++c) {
      if (!mask[w.index(c, r)]) continue;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr;
          const int cc = c + dc;
          if (rr >= 0 && cc >= 0 && rr < w.height && cc < w.width) out[w.index(cc, rr)] = 1;
        }
      }
    }
  }
  return out;
}

// True if a beam of `scan` truly hits `object` inside `cell`.
bool hitsCell(const SimScan& scan, const LaserParams& l, int object, const CellIndex& cell,
              double res) {
  for (std::size_t b = 0; b < scan.hit_object.size(); ++b) {
    if (scan.hit_object[b] != object) continue;
    const double bearing = scan.sensor_pose.theta + l.angleMin() + b * l.angleIncrement();
    const double x = scan.sensor_pose.x + scan.true_ranges[b] * std::cos(bearing);
    const double y = scan.sensor_pose.y + scan.true_ranges[b] * std::sin(bearing);
    if (static_cast<std::int64_t>(std::floor(x / res)) == cell.x &&
        static_cast<std::int64_t>(std::floor(y / res)) == cell.y) {
      return true;
    }
  }
  return false;
}

}  // namespace

std::vector<PolicyRun> standardPolicies(double resolution) {
  std::vector<PolicyRun> runs;
  auto add = [&runs, resolution](PolicyType type, InitValue init) {
    PolicyRun r;
    r.params = MapParams::defaultsFor(type);
    r.params.grid.resolution = resolution;
    r.params.policy.init = init;
    r.label = std::string(toString(type)) + " / " + toString(init);
    runs.push_back(r);
  };
  add(PolicyType::kNone, InitValue::kUnknown);
  for (PolicyType t :
       {PolicyType::kMax, PolicyType::kClamp, PolicyType::kForget, PolicyType::kClampLower}) {
    add(t, InitValue::kUnknown);
    add(t, InitValue::kEmptyBound);
  }
  return runs;
}

std::vector<WorldEvent> findEvents(const World& world, const std::vector<SimScan>& scans,
                                   double resolution) {
  std::vector<WorldEvent> events;
  for (std::size_t i = 0; i < world.objects.size(); ++i) {
    const WorldObject& o = world.objects[i];
    WorldEvent e;
    e.object = static_cast<int>(i);
    e.name = o.name;
    if (o.role == ObjectRole::kDeparting) {
      e.type = WorldEvent::Type::kDeparture;
      e.start_time = departureStart(o);
      const Polygon parked = o.polygonAt(e.start_time);
      double t = e.start_time;
      while (t < world.duration && o.presentAt(t) && polygonsIntersect(o.polygonAt(t), parked)) {
        t += kFootprintStep;
      }
      e.event_time = t;
    } else if (o.role == ObjectRole::kArriving) {
      e.type = WorldEvent::Type::kArrival;
      e.start_time = std::isfinite(o.appear_time) ? o.appear_time : 0.0;
      e.event_time = o.trajectory.empty() ? e.start_time : o.trajectory.waypoints.back().t;
    } else {
      continue;
    }
    // Cells that saw the object: while parked before a departure, once parked after an arrival.
    std::map<std::pair<std::int64_t, std::int64_t>, int> hits;
    for (const SimScan& s : scans) {
      const bool parked =
          e.type == WorldEvent::Type::kDeparture ? s.stamp < e.start_time : s.stamp >= e.event_time;
      if (!parked) continue;
      const LaserParams& l = world.vehicle.lasers[static_cast<std::size_t>(s.laser)];
      for (std::size_t b = 0; b < s.hit_object.size(); ++b) {
        if (s.hit_object[b] != e.object) continue;
        const double bearing = s.sensor_pose.theta + l.angleMin() + b * l.angleIncrement();
        const double x = s.sensor_pose.x + s.true_ranges[b] * std::cos(bearing);
        const double y = s.sensor_pose.y + s.true_ranges[b] * std::sin(bearing);
        ++hits[{static_cast<std::int64_t>(std::floor(x / resolution)),
                static_cast<std::int64_t>(std::floor(y / resolution))}];
      }
    }
    for (const auto& [cell, n] : hits) {
      if (n >= kMinHits) e.cells.push_back(CellIndex{cell.first, cell.second});
    }
    // First scan after the event that observes each cell: sees it free (departure) or hits it
    // (arrival). Cells never observed again say nothing about the map and are dropped.
    std::vector<CellIndex> kept;
    for (const CellIndex& c : e.cells) {
      for (std::size_t j = 0; j < scans.size(); ++j) {
        const SimScan& s = scans[j];
        if (s.stamp < e.event_time) continue;
        const LaserParams& l = world.vehicle.lasers[static_cast<std::size_t>(s.laser)];
        const bool observed = e.type == WorldEvent::Type::kDeparture
                                  ? seenFree(s, l, c, resolution)
                                  : hitsCell(s, l, e.object, c, resolution);
        if (observed) {
          kept.push_back(c);
          e.first_view.push_back(j);
          break;
        }
      }
    }
    e.cells.swap(kept);
    events.push_back(e);
  }
  return events;
}

PolicyResult evaluatePolicy(const World& world, const std::vector<SimScan>& scans,
                            const std::vector<WorldEvent>& events, const PolicyRun& run,
                            const EvaluationOptions& options) {
  PolicyResult result;
  result.label = run.label;
  result.params = run.params;
  result.events.resize(events.size());
  WaveletMap map(run.params);

  auto has_switched = [&map](const WorldEvent& e, const CellIndex& c) {
    const float v = map.value(c);
    return e.type == WorldEvent::Type::kDeparture ? v < -kDecisionMargin : v > kDecisionMargin;
  };
  auto mean_reflection = [&map](const WorldEvent& e) {
    double sum = 0.0;
    std::size_t n = 0;
    for (const CellIndex& c : e.cells) {
      const float p = map.reflection(c);
      if (std::isnan(p)) continue;
      sum += p;
      ++n;
    }
    return n > 0 ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
  };
  auto mean_occupancy = [&map](const WorldEvent& e) {
    double sum = 0.0;
    for (const CellIndex& c : e.cells) sum += probabilityFromLogOdds(map.value(c));
    return e.cells.empty() ? 0.0 : sum / static_cast<double>(e.cells.size());
  };

  // Per event and cell: the scan index at which the cell switched (kNever: not yet).
  constexpr std::size_t kNever = std::numeric_limits<std::size_t>::max();
  std::vector<std::vector<std::size_t>> switched_at(events.size());
  std::vector<double> next_sample(events.size());
  for (std::size_t k = 0; k < events.size(); ++k) {
    switched_at[k].assign(events[k].cells.size(), kNever);
    next_sample[k] = std::max(0.0, events[k].start_time - 2.0);
  }
  double total = 0.0;
  double worst = 0.0;
  using Clock = std::chrono::steady_clock;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const SimScan& s = scans[i];
    const LaserParams& l = world.vehicle.lasers[static_cast<std::size_t>(s.laser)];
    const Clock::time_point t0 = Clock::now();
    map.integrate(s.sensor_pose, s.view(l));
    const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
    total += dt;
    worst = std::max(worst, dt);

    for (std::size_t k = 0; k < events.size(); ++k) {
      const WorldEvent& e = events[k];
      for (std::size_t c = 0; c < e.cells.size(); ++c) {
        if (switched_at[k][c] == kNever && e.first_view[c] <= i && has_switched(e, e.cells[c])) {
          switched_at[k][c] = i;
        }
      }
      EventResponse& r = result.events[k];
      while (s.stamp >= next_sample[k]) {
        r.times.push_back(next_sample[k]);
        r.mean_occupancy.push_back(mean_occupancy(e));
        if (run.params.reflection) r.mean_reflection.push_back(mean_reflection(e));
        next_sample[k] += options.sample_period;
      }
    }
  }
  // An event's response: the `fraction` quantile of its cells' delays from first view to switch.
  for (std::size_t k = 0; k < events.size(); ++k) {
    const WorldEvent& e = events[k];
    std::vector<std::pair<std::size_t, double>> delays;  // (scans, seconds); kNever: never
    for (std::size_t c = 0; c < e.cells.size(); ++c) {
      const std::size_t at = switched_at[k][c];
      delays.emplace_back(at == kNever ? kNever : at - e.first_view[c] + 1,
                          at == kNever ? std::numeric_limits<double>::infinity()
                                       : scans[at].stamp - scans[e.first_view[c]].stamp);
    }
    if (delays.empty()) continue;
    std::sort(delays.begin(), delays.end());
    const auto rank =
        static_cast<std::size_t>(std::ceil(options.fraction * static_cast<double>(delays.size())));
    const std::size_t q = std::min(delays.size(), std::max<std::size_t>(rank, 1)) - 1;
    result.events[k].scans = delays[q].first;
    result.events[k].seconds = delays[q].second;
  }
  result.total_s = total;
  result.mean_scan_us = scans.empty() ? 0.0 : 1e6 * total / static_cast<double>(scans.size());
  result.max_scan_us = 1e6 * worst;

  // Final map over the region of interest against the final ground truth.
  const CellBox box = map.boxAround(world.region_min.x(), world.region_min.y(),
                                    world.region_max.x(), world.region_max.y(), 0);
  result.final_map = map.exportScale(0, box, Aggregation::kMean);
  GridWindow window;
  window.resolution = run.params.grid.resolution;
  window.min_x = box.min_x;
  window.min_y = box.min_y;
  window.width = static_cast<int>(box.width());
  window.height = static_cast<int>(box.height());
  const double t_end = scans.empty() ? 0.0 : scans.back().stamp;
  const std::vector<std::uint8_t> surface = surfaceAt(world, t_end, window);
  const std::vector<std::uint8_t> near_surface = dilate(surface, window);
  std::vector<std::uint8_t> occupied(window.size(), 0);
  for (std::size_t i = 0; i < window.size(); ++i) {
    occupied[i] = result.final_map.known[i] && result.final_map.log_odds[i] > kDecisionMargin;
  }
  const std::vector<std::uint8_t> near_occupied = dilate(occupied, window);
  std::size_t occ = 0, occ_ok = 0, seen_surface = 0, seen_surface_ok = 0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    occ += occupied[i];
    occ_ok += occupied[i] && near_surface[i];
    if (surface[i] && result.final_map.known[i]) {
      ++seen_surface;
      seen_surface_ok += near_occupied[i];
    }
  }
  result.occupied_cells = occ;
  result.precision = occ ? static_cast<double>(occ_ok) / static_cast<double>(occ) : 0.0;
  result.recall =
      seen_surface ? static_cast<double>(seen_surface_ok) / static_cast<double>(seen_surface) : 0.0;

  // Wall thickness: occupied cells nearer to a wall than to anything else, within the margin.
  const std::vector<float> to_wall =
      distanceTransform(occupancyAt(world, t_end, window, TruthFilter::kWallsOnly), window);
  std::vector<std::uint8_t> others = occupancyAt(world, t_end, window, TruthFilter::kAll);
  const std::vector<std::uint8_t> walls =
      occupancyAt(world, t_end, window, TruthFilter::kWallsOnly);
  for (std::size_t i = 0; i < others.size(); ++i) others[i] = others[i] && !walls[i];
  const std::vector<float> to_other = distanceTransform(others, window);
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    if (occupied[i] && to_wall[i] <= options.wall_margin && to_wall[i] < to_other[i]) {
      sum += to_wall[i];
      ++n;
    }
  }
  result.wall_distance = n ? sum / static_cast<double>(n) : 0.0;
  if (run.params.ndt) {
    result.ndt_walls =
        ndtWallDistance(world, t_end, result.final_map, map.exportNdt(0, box), options.wall_margin);
  }

  const MapStats stats = map.stats(true);
  result.ndt_cells = stats.ndt_cells;
  result.ndt_bytes = stats.ndt_bytes;
  result.nodes = stats.nodes;
  result.bytes = stats.bytes;
  result.observed_cells = stats.observed_cells;
  result.bytes_per_observed_cell =
      stats.observed_cells
          ? static_cast<double>(stats.bytes) / static_cast<double>(stats.observed_cells)
          : 0.0;
  return result;
}

int forgettingScansToFree(double x0, double gamma, double odd_emp) {
  if (x0 < 0.0) return 0;
  // (1-g)^n (x0 - e) + e < 0  <=>  n > log(-e / (x0 - e)) / log(1 - g).
  const double bound = std::log(-odd_emp / (x0 - odd_emp)) / std::log(1.0 - gamma);
  return static_cast<int>(std::floor(bound)) + 1;
}

int additiveScansToFree(double x0, double odd_emp) {
  if (x0 < 0.0) return 0;
  return static_cast<int>(std::floor(x0 / -odd_emp)) + 1;
}

}  // namespace sim
}  // namespace wavog
