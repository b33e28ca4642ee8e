// Shared fixtures of the core tests: parameter sets for every policy, seeded random scans with
// every kind of bad beam, and the tree-versus-reference comparison.
#ifndef WAVOG_MAPPING_TEST_CORE_TEST_SUPPORT_H_
#define WAVOG_MAPPING_TEST_CORE_TEST_SUPPORT_H_

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "dense_reference.h"
#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_test {

/// One named configuration per policy (and per initial value where it matters).
struct NamedParams {
  std::string name;
  wavog::MapParams params;
};
std::vector<NamedParams> everyPolicy(double resolution, int block_levels);
/// everyPolicy(), then forget eager ("forget_eager") and pruned with skipping
/// ("forget_pruned_skip"), then, for each configuration of everyPolicy() (in its order) named in
/// `payload_policies`, one with the payloads: reflection layers and normal-distribution cells
/// ("<name>_reflection_ndt"; forget then in seconds, half-life 0.2 s).
std::vector<NamedParams> everyPolicyWithVariants(double resolution, int block_levels,
                                                 const std::vector<std::string>& payload_policies);
/// The six policies, in PolicyType's order.
std::vector<wavog::PolicyType> everyPolicyType();

/// A scan with its own storage.
struct OwnedScan {
  wavog::Pose2 pose;
  std::vector<float> ranges;
  double angle_min = 0, angle_increment = 0, range_min = 0, range_max = 0;
  wavog::ScanView view() const;
};

/// Seeded random scans around the origin inside a square of half-size `half_extent` metres:
/// random pose, beam count, field of view (up to 2 pi), sign of the increment; ranges mix valid
/// readings with NaN, +inf, -inf, 0, below range_min and beyond range_max.
class RandomScans {
 public:
  RandomScans(std::uint32_t seed, double half_extent) : rng_(seed), half_(half_extent) {}
  OwnedScan next();

 private:
  std::mt19937 rng_;
  double half_;
};

/// The next `n` scans of `scans` into each of `mappers` (maps or references), scan by scan.
template <typename... Mappers>
void integrateScans(RandomScans* scans, int n, Mappers&... mappers) {
  for (int i = 0; i < n; ++i) {
    const OwnedScan s = scans->next();
    (mappers.integrate(s.pose, s.view()), ...);
  }
}

/// Every finest cell of [-half, half)^2: the same observed flag in `a` and `b`, and values within
/// `tolerance` * max(1, |b|) (0: equal).
void expectSameCells(const wavog::WaveletMap& a, const wavog::WaveletMap& b, int half,
                     double tolerance);

/// Largest |tree - reference| / max(1, |reference|) over the reference's extent, and the number
/// of cells whose observed flag differs.
struct Comparison {
  double max_rel_error = 0;
  std::int64_t worst_x = 0, worst_y = 0;
  std::size_t knowledge_mismatches = 0;
};
Comparison compare(const wavog::WaveletMap& map, const DenseReference& ref);

/// Directory of ../shared/data (or $WAVOG_DATA_DIR); fails the test when missing.
std::string dataDir();

/// The first `n` scans of fr079-corrected.log.gz as scans with their own storage, each placed at
/// its logged laser pose (empty, and the test failed, when the data set is missing).
std::vector<OwnedScan> fr079Scans(std::size_t n);

}  // namespace wavog_test

#endif  // WAVOG_MAPPING_TEST_CORE_TEST_SUPPORT_H_
