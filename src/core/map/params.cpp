#include "wavog_mapping/core/params.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "wavog_mapping/core/limits.h"
#include "wavog_mapping/core/types.h"

namespace wavog {
namespace {

struct PolicyName {
  PolicyType type;
  const char* name;
};
constexpr PolicyName kPolicyNames[] = {
    {PolicyType::kNone, "none"},
    {PolicyType::kMax, "max"},
    {PolicyType::kClamp, "clamp"},
    {PolicyType::kForget, "forget"},
    {PolicyType::kClampLower, "clamp_lower"},
    {PolicyType::kClampUpper, "clamp_upper"},
};

// Appends "<name> (<value>) must be <rule>" when `ok` is false.
void check(bool ok, const char* name, double value, const char* rule,
           std::vector<std::string>* out) {
  if (ok) return;
  std::ostringstream s;
  s << name << " (" << value << ") must be " << rule;
  out->push_back(s.str());
}

constexpr int kMaxThreads = 256;

bool usesLowerClamp(PolicyType t) {
  return t == PolicyType::kClamp || t == PolicyType::kClampLower;
}

}  // namespace

const char* toString(PolicyType type) {
  for (const auto& p : kPolicyNames) {
    if (p.type == type) return p.name;
  }
  return "unknown";
}

const char* toString(InitValue init) {
  return init == InitValue::kUnknown ? "unknown" : "empty_bound";
}

bool fromString(const std::string& name, PolicyType* type) {
  for (const auto& p : kPolicyNames) {
    if (name == p.name) {
      *type = p.type;
      return true;
    }
  }
  return false;
}

bool fromString(const std::string& name, InitValue* init) {
  if (name == "unknown") {
    *init = InitValue::kUnknown;
    return true;
  }
  if (name == "empty_bound") {
    *init = InitValue::kEmptyBound;
    return true;
  }
  return false;
}

std::vector<std::string> MapParams::validate() const {
  std::vector<std::string> v;
  const auto finite = [](double x) { return std::isfinite(x); };
  check(finite(grid.resolution) && grid.resolution > 0.001 && grid.resolution <= 100.0,
        "resolution", grid.resolution, "in (0.001, 100] m", &v);
  check(grid.block_levels >= 2 && grid.block_levels <= 12, "block_levels", grid.block_levels,
        "an integer in [2, 12]", &v);
  check(finite(sensor.odd_occ) && sensor.odd_occ > 0.0 && sensor.odd_occ <= 50.0, "odd_occ",
        sensor.odd_occ, "in (0, 50] log-odds", &v);
  check(finite(sensor.odd_emp) && sensor.odd_emp < 0.0 && sensor.odd_emp >= -50.0, "odd_emp",
        sensor.odd_emp, "in [-50, 0) log-odds", &v);
  check(finite(sensor.band_width) && sensor.band_width >= 0.0 && sensor.band_width <= 10.0,
        "band_width", sensor.band_width, "in [0, 10] m (0: one cell)", &v);
  // Only where both are valid on their own (else their own rules name them).
  if (finite(grid.resolution) && grid.resolution > 0.001 && grid.resolution <= 100.0 &&
      finite(sensor.band_width) && sensor.band_width <= 10.0 &&
      sensor.band_width / grid.resolution > kMaxBandCells) {
    // The band's cells are walked one by one (limits.h): a band this wide at this resolution
    // would take most of a scan's work budget on its own.
    std::ostringstream s;
    s << "band_width (" << sensor.band_width << " m) must be at most " << kMaxBandCells
      << " cells at resolution (" << grid.resolution
      << " m), i.e. <= " << kMaxBandCells * grid.resolution << " m (or a coarser resolution)";
    v.push_back(s.str());
  }
  check(finite(sensor.max_range) && sensor.max_range >= 0.0, "max_range", sensor.max_range,
        ">= 0 m (0: the scan's range_max)", &v);
  check(finite(sensor.no_return_clear) && sensor.no_return_clear >= 0.0, "no_return_clear",
        sensor.no_return_clear, ">= 0 m (0: no-return beams clear nothing)", &v);
  check(finite(policy.gamma) && policy.gamma > 0.0 && policy.gamma <= 1.0, "gamma", policy.gamma,
        "in (0, 1]", &v);
  check(finite(policy.forget_half_life) && policy.forget_half_life >= 0.0 &&
            policy.forget_half_life <= 1e6,
        "forget_half_life", policy.forget_half_life, "in [0, 1e6] s (0: off, gamma per scan)", &v);
  check(finite(policy.clamp_min) && policy.clamp_min < 0.0, "clamp_min", policy.clamp_min,
        "< 0 log-odds", &v);
  check(finite(policy.clamp_max) && policy.clamp_max > 0.0, "clamp_max", policy.clamp_max,
        "> 0 log-odds", &v);
  check(finite(prune_threshold) && prune_threshold >= 0.0 && prune_threshold <= 1.0,
        "prune_threshold", prune_threshold, "in [0, 1] log-odds", &v);
  check(finite(skip_tolerance) && skip_tolerance >= 0.0 && skip_tolerance <= 1.0, "skip_tolerance",
        skip_tolerance, "in [0, 1] log-odds", &v);
  check(num_threads >= 0 && num_threads <= kMaxThreads, "num_threads", num_threads,
        "an integer in [0, 256] (0: one per core)", &v);
  check(finite(ndt_min_weight) && ndt_min_weight >= 0.0 && ndt_min_weight <= 1e6, "ndt_min_weight",
        ndt_min_weight, "in [0, 1e6] (end-points)", &v);
  check(finite(ndt_max_weight) && ndt_max_weight >= 1.0 && ndt_max_weight <= 1e9, "ndt_max_weight",
        ndt_max_weight, "in [1, 1e9] (end-points)", &v);
  if (!region.all && grid.block_levels >= 2 && grid.block_levels <= 12) {
    const std::int64_t lim = kCellIndexLimit >> grid.block_levels;
    const auto inside = [lim](std::int64_t b) { return b >= -lim && b <= lim; };
    if (!(region.min_bx < region.max_bx && region.min_by < region.max_by && inside(region.min_bx) &&
          inside(region.max_bx) && inside(region.min_by) && inside(region.max_by))) {
      std::ostringstream s;
      s << "region (blocks [" << region.min_bx << ", " << region.max_bx << ") x ["
        << region.min_by << ", " << region.max_by
        << ")) must be a non-empty box of blocks, min < max on each axis, within +-" << lim
        << " blocks (the extent)";
      v.push_back(s.str());
    }
  }
  // clamp_min < clamp_max needs no rule of its own: the two rules above force their signs.
  return v;
}

std::vector<std::string> MapParams::warnings() const {
  std::vector<std::string> w;
  if (!ndt) return w;
  // A cell that takes one end-point per scan holds 1 end-point's worth of them at least (the
  // floor is in end-points of the scan, integrate.cpp): only a floor over 1 can defeat it, or a
  // cap under the floor.
  const bool capped = policy.type == PolicyType::kClamp || policy.type == PolicyType::kClampUpper;
  std::ostringstream s;
  if (capped && ndt_max_weight < ndt_min_weight) {
    s << "ndt_max_weight (" << ndt_max_weight << ") is under ndt_min_weight (" << ndt_min_weight
      << ") with policy " << toString(policy.type)
      << ": every Gaussian is capped under the floor and dropped, none is kept";
  } else if (ndt_min_weight > 1.0) {
    s << "ndt_min_weight (" << ndt_min_weight << ") is over 1 end-point: a cell keeps a Gaussian "
      << "only when one scan puts at least " << ndt_min_weight << " end-points in it, so a "
      << "wall seen with one end-point per cell and scan keeps none (<= 1 keeps every one)";
  }
  if (!s.str().empty()) w.push_back(s.str());
  return w;
}

MapParams MapParams::defaultsFor(PolicyType type) {
  MapParams p;  // the field initialisers: the "forget" policy's defaults
  p.policy.type = type;
  if (type != PolicyType::kForget) {
    p.sensor.odd_occ = SensorModelParams::kAdditiveOddOcc;
    p.sensor.odd_emp = SensorModelParams::kAdditiveOddEmp;
  }
  return p;
}

double MapParams::initValue() const {
  if (policy.init == InitValue::kUnknown) return 0.0;
  return usesLowerClamp(policy.type) ? policy.clamp_min : sensor.odd_emp;
}

void throwIfInvalid(const MapParams& params) {
  const auto errors = params.validate();
  if (errors.empty()) return;
  std::string msg = "invalid map parameters:";
  for (const auto& e : errors) msg += "\n  " + e;
  throw std::invalid_argument(msg);
}

}  // namespace wavog
