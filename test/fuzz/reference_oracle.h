// The differential oracle of fuzz_integrate: a map against the dense cell-by-cell reference
// (test/core/dense_reference.h). A disagreement prints the cell and aborts the run.
#ifndef WAVOG_MAPPING_TEST_FUZZ_REFERENCE_ORACLE_H_
#define WAVOG_MAPPING_TEST_FUZZ_REFERENCE_ORACLE_H_

#include "dense_reference.h"
#include "wavog_mapping/core/wavelet_map.h"

namespace wavog_fuzz {

/// A metric rectangle [min_x, max_x] x [min_y, max_y] (map frame), as clearBox takes it.
struct Box {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
};

/// Every finest cell of the reference's extent (read out at scale 0; value() / isObserved() on a
/// lattice of them) equals the reference, or, when `cleared` is given, is back at the prior and
/// unobserved if its centre lies in the box.
void expectCellsEqual(const wavog::WaveletMap& map, const wavog_test::DenseReference& ref,
                      const Box* cleared, const char* when);
/// Mean, max and knowledge of every coarse cell at scales 1..max_scale inside the extent.
void expectScalesEqual(const wavog::WaveletMap& map, const wavog_test::DenseReference& ref,
                       int max_scale);

}  // namespace wavog_fuzz

#endif  // WAVOG_MAPPING_TEST_FUZZ_REFERENCE_ORACLE_H_
