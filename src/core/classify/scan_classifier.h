// The scan classifier: the class (E / O / U, ALGORITHM.md section 3.2) of a finest cell, of a
// square of cells and of a 4 x 4 group of cells against one prepared scan, without a map.
// A square's class is conservative (never E or U wrongly, FREE_OR_UNKNOWN only without O) and
// carries the beams that may meet it, which its sub-squares and cells inherit: inside one sector
// ranges alone decide; within under 90 deg of sectors the boundary rays are tested by cross
// products, without bearings. A cell gets exactly the class the dense reference (test/core)
// gives it. The definitions are inline (scan_classifier_*_inl.h): they are the integration's
// inner loop. Not installed; included only by src/core/* and the core tests.
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_H_

#include <array>
#include <cstdint>
#include <limits>

#include "classify/prepared_scan.h"
#include "wavog_mapping/core/types.h"

namespace wavog {
namespace detail {

/// What classifying a square learned: its class and the beams whose sectors may meet it, which
/// its sub-squares and cells inherit (they lie inside it).
struct SquareInfo {
  CellClass cls = CellClass::kMixed;
  int jlo = 0, jhi = -1;  ///< beams whose sector may hold a point of the square (a superset)
  bool single = false;    ///< every point of the square lies in sector jlo (jlo == jhi), in the fan
  bool narrow = false;    ///< its directions and sectors span under pi / 2: the sub-squares and
                          ///< cells find theirs by testing the boundaries (no bearings)
  int slo = 0, shi = -1;  ///< narrow: the sectors that may hold a point of the square, with -1 and
                          ///< n standing for outside the fan, before boundary 0 / past boundary n
};

/// Classes of a group of finest cells as bit masks (one bit per cell): E, O, and U for neither.
struct CellMasks {
  std::uint32_t e = 0, o = 0;
};

/// The classes of the 64 cells of an 8 x 8 tile, cell (x, y) at bit x + 8 y: E, O, U for neither.
struct TileMasks {
  std::uint64_t e = 0, o = 0;
};

class ScanClassifier {
 public:
  /// Prepares `scan` taken from `pose` (see PreparedScan::prepare); beam counts go to `st`.
  ScanStatus prepare(const MapParams& params, const Pose2& pose, const ScanView& scan,
                     IntegrateStats* st);
  const PreparedScan& scan() const { return s_; }
  /// Releases the per-scan buffers if one absurd scan grew them (PreparedScan::releaseIfLarge).
  void releaseIfLarge() { s_.releaseIfLarge(); }

  /// Class of the square of side 2^l cells at cell (ix0, iy0).
  SquareInfo classifySquare(int l, std::int64_t ix0, std::int64_t iy0) const;
  /// The same for a sub-square of a square classified as `parent` (cheaper, as conservative).
  SquareInfo classifySquare(int l, std::int64_t ix0, std::int64_t iy0,
                            const SquareInfo& parent) const;
  /// Exact class (E, O or U) of finest cell (ix, iy) of a square classified as `square`.
  CellClass classifyCell(std::int64_t ix, std::int64_t iy, const SquareInfo& square) const;
  /// True when classify4x4() applies to `square`: its cells lie in one or at most kFewSectors
  /// sectors, known without bearings.
  static bool fewSectors(const SquareInfo& square) {
    return square.single || (square.narrow && square.shi - square.slo < kFewSectors);
  }
  /// classifyCell() for the 16 cells of the 4 x 4 square at (ix0, iy0) classified as `square`
  /// (fewSectors(square)), as masks: bit x + 4 y for cell (ix0 + x, iy0 + y).
  CellMasks classify4x4(std::int64_t ix0, std::int64_t iy0, const SquareInfo& square) const;
  /// classifyCell() for the cells of the tile of level t (storage/tile.h: 8 x 8, or 4 x 4 for
  /// t = 2) at (ix0, iy0) classified as `square`, as masks (bit x + 8 y): by row runs where its
  /// cells lie in few sectors, else by 4 x 4 groups or cell by cell.
  TileMasks classifyTileCells(int t, std::int64_t ix0, std::int64_t iy0,
                              const SquareInfo& square) const;
  /// classifyCell() for the 16 cells of a 4 x 4 square classified as `square` (any class).
  CellMasks classifyGroup(std::int64_t ix0, std::int64_t iy0, const SquareInfo& square) const;

  /// classifyCell() for the 64 cells of the 8 x 8 square at (ix0, iy0) classified as `square`
  /// (fewSectors(square)), by row runs (scan_classifier_tile_inl.h), into *out; false (out
  /// untouched) when more than kTileMaxBoundaries boundaries would have to be located.
  bool classifyTile(std::int64_t ix0, std::int64_t iy0, const SquareInfo& square,
                    TileMasks* out) const;

  static constexpr int kFewSectors = 32;
  /// classifyTile() locates up to this many boundaries (between runs of sectors) in the tile, else
  /// the cells are classified one by one: a boundary costs about 70 instructions for the tile's 8
  /// rows, a cell about 40 (callgrind, fr079 at 5 cm: 10 and 12 both -3.8 % per scan against the
  /// row runs alone without clearing, 10 -1.4 % with 80 m clearing; 8 and 16 less).
  static constexpr int kTileMaxBoundaries = 10;

 private:
  /// An axis-aligned square of the map frame, in metres.
  struct Square {
    double x0, y0, x1, y1;
  };

  CellClass cellAt(std::size_t j, double d2) const;
  static void placeGroup(const CellMasks& g, unsigned shift, TileMasks* m);
  /// Bounds of the squared distances of a tile's cells.
  struct TileRange {
    double lo, hi;
  };
  void classifySector(int j, std::uint64_t cells, const double* a2, const double* l2,
                      const TileRange& d2, TileMasks* m) const;
  /// A sector's cells over a tile: all E, all U, or some of each.
  enum class SectorKind { kEmpty, kUnknown, kMixed };
  SectorKind sectorKind(int j, const TileRange& d2) const;
  bool isHitCell(std::int64_t ix, std::int64_t iy, const SquareInfo& box) const;
  template <std::size_t kSide>
  void classifyGroups(std::int64_t ix0, std::int64_t iy0, const SquareInfo& box,
                      CellMasks* out) const;
  template <std::size_t kGroups>
  void hitMasks(const std::uint32_t* keys, const SquareInfo& box, std::uint32_t* hit) const;
  template <std::size_t kSide>
  bool quadrantCoeffs(const std::array<double, kSide>& dx, const std::array<double, kSide>& dy,
                      std::array<double, kSide>* dc, std::array<double, kSide>* dr,
                      std::array<double, kSide>* nc, std::array<double, kSide>* nr) const;
  long beamOf(double dx, double dy) const;
  long sectorIn(double dx, double dy, const SquareInfo& box, int start) const;
  int lastSurelyPast(double dx, double dy, double tol, int lo, int hi) const;
  int lastNotSurelyBefore(double dx, double dy, double tol, int lo, int hi) const;
  double nearest2(const Square& sq) const;
  double farthest2(const Square& sq) const;
  Square square(int l, std::int64_t ix0, std::int64_t iy0) const;
  void extremeCorners(const Square& sq, double* ax, double* ay, double* bx, double* by) const;
  void beamRange(double a_lo, double a_hi, long* jlo, long* jhi) const;
  SquareInfo classifyInRange(int l, std::int64_t ix0, std::int64_t iy0,
                             const SquareInfo& parent) const;
  CellClass rangeClass(const Square& sq, int jlo, int jhi, bool partial) const;
  CellClass classifyInBeam(int l, std::int64_t ix0, std::int64_t iy0, int j) const;

  /// quadrantBuckets()' coefficients for one sign pair: D = dx * (cell dx) + dy * (cell dy),
  /// the numerator nx * (cell dx) + ny * (cell dy) (map-frame offsets).
  struct QuadrantCoeffs {
    double dx = 0, dy = 0, nx = 0, ny = 0;
  };

  PreparedScan s_;
  double reach2_ = 0;                         // squaredLimit(s_.reach)
  std::array<QuadrantCoeffs, 4> quadrant_{};  // by sign pair: bit 0 X < 0, bit 1 Y < 0
};

}  // namespace detail
}  // namespace wavog

#include "classify/scan_classifier_cells_inl.h"
#include "classify/scan_classifier_squares_inl.h"
#include "classify/scan_classifier_tile_inl.h"

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_H_
