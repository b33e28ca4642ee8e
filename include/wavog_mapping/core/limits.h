// The representable extent of a map and the bounds on the work of one call: the limits every entry
// point checks before it computes an index, touches a block or allocates. Units: cells, blocks and
// metres as named. Plain constants and pure functions, safe from any thread.
#ifndef WAVOG_MAPPING_CORE_LIMITS_H_
#define WAVOG_MAPPING_CORE_LIMITS_H_

#include <cstddef>
#include <cstdint>

#include "wavog_mapping/core/params.h"
#include "wavog_mapping/core/types.h"

namespace wavog {

/// Finest cell indices of the representable extent: [-kCellIndexLimit, kCellIndexLimit) on both
/// axes (2^30 cells: 53,687 km at 5 cm). Block keys, stored in 32 bits, then always fit: a block
/// index lies in [-kCellIndexLimit >> block_levels, kCellIndexLimit >> block_levels). A scan whose
/// pose plus reach leaves the extent is refused (ScanStatus::kOutOfExtent); a map file with a block
/// outside it is refused (MapIoError); clearBox and cell look-ups clamp to it.
constexpr std::int64_t kCellIndexLimit = std::int64_t{1} << 30;
/// True if finest cell (ix, iy) lies in the extent.
inline bool inExtent(std::int64_t ix, std::int64_t iy) {
  return ix >= -kCellIndexLimit && ix < kCellIndexLimit && iy >= -kCellIndexLimit &&
         iy < kCellIndexLimit;
}
/// A whole number of cells (e.g. floor(x / resolution)) as an index clamped to one cell beyond
/// the extent on each side, [-kCellIndexLimit - 1, kCellIndexLimit]; NaN gives kCellIndexLimit.
/// The one float-to-index conversion of the core's entry points: never an overflowing cast.
std::int64_t clampedCellIndex(double cells);

/// Hard range limit in cells: a reading at or beyond the hard range limit (hardRangeLimit()) is a
/// no return (REP 117), and no_return_clear is capped to it, whatever max_range and range_max say.
/// At most kMaxRangeCells cells (3,276.8 m at 5 cm, 655.36 m at 1 cm) ...
constexpr double kMaxRangeCells = 65536.0;
/// ... and at most kMaxRangeBlocks blocks (block side 2^block_levels cells), so that the block
/// loop of one scan classifies at most (2 * kMaxRangeBlocks + 2)^2 blocks (binds below
/// block_levels 8) ...
constexpr double kMaxRangeBlocks = 256.0;
/// ... and at most kMaxScanBeamCells / beams cells: the tree work of one scan follows its beams
/// times their length in cells (measured worst case, random ranges up to the limit: about 1.7
/// nodes visited per beam-cell), so this bounds it to about 1.4e7 nodes (2^23 beam-cells: 361
/// beams reach 23,237 cells, 1,081 beams 7,760, 4,096 beams 2,048; 1,160 m / 388 m / 102 m at
/// 5 cm).
constexpr double kMaxScanBeamCells = 8388608.0;
/// The hard range limit (m) of a scan of `beams` beams on `grid` with an occupied band of one
/// cell: the smallest of the three above.
double hardRangeLimit(const GridParams& grid, std::size_t beams);
/// Widest occupied band, in cells (band_width / resolution): 512. A wider one is refused by
/// MapParams::validate(), naming band_width and resolution (a band of 10 m is allowed from a
/// resolution of 1.96 cm). Its cells alone (pi B^2 for a whole turn, below) then take at most a
/// tenth of kMaxScanBeamCells.
constexpr double kMaxBandCells = 512.0;
/// The hard range limit (m) of a scan of `beams` beams, `angle_increment` apart, under `params`:
/// hardRangeLimit(grid, beams), and a wider occupied band of B = band_width / resolution cells
/// counted against the same budget. The walk visits every cell of a hit's band one by one (no
/// square of O cells is updated whole), about as many nodes per cell as per beam-cell; the bands
/// of returns up to L cells hold at most fov (B - 1) (L + B / 2) cells beyond the one-cell band
/// (fov = beams |angle_increment| <= 2 pi), so L is capped at
/// (kMaxScanBeamCells - fov (B - 1) B / 2) / (beams + fov (B - 1)): one scan's tree work stays
/// near 1.4e7 nodes for every band_width (at 1.01 mm, band_width 0.3 m, 8 beams over a turn
/// returning at the limit: L = 4.4 m and 1.36e7 nodes; without the cap 66 m and 2.06e8 nodes).
/// A one-cell band (band_width <= resolution) leaves hardRangeLimit(grid, beams).
double hardRangeLimit(const MapParams& params, std::size_t beams, double angle_increment);

/// Largest |angle_min| (rad) a scan may have; beyond it, refused as kBadGeometry (bearings stay
/// exact to 1e-14 rad below it; drivers send values in [-2 pi, 2 pi]).
constexpr double kMaxAbsAngleMin = 100.0;
/// Smallest |angle_increment| (rad); below it, refused as kBadGeometry (1e-7 rad: 63 million beams
/// per turn, far finer than any scanner).
constexpr double kMinAbsAngleIncrement = 1e-7;
/// Most beams in one scan (2^24); more is refused as kBadGeometry.
constexpr std::size_t kMaxBeams = std::size_t{1} << 24;
/// Per-thread scan buffers sized for more beams than this (2^16) are released after the scan, so
/// one absurd scan does not stay resident.
constexpr std::size_t kScratchKeepBeams = std::size_t{1} << 16;

/// Largest |log-odds| of a block average or a stored detail in a map file (1e30); a file holding a
/// larger one is refused (MapIoError). Below it a cell's value (the average plus at most three
/// details per level, 12 levels) stays under 4e31, so the details an update writes back (doubles
/// since issue 37, floats in files before version 6; at most the largest |value| of the cells they
/// combine) stay far under FLT_MAX: every update keeps the map finite, and a map holds nothing an
/// older build could not. The updates themselves stay far below it (|odd| <= 50 per scan); the
/// details and averages they write are kept within it (saturated, update/map_slot.h keepStored)
/// also where a loaded file's cells lie beyond it, so that every map saves a file that loads.
constexpr double kMaxStoredLogOdds = 1e30;

/// Largest read-out, in raster cells (2^26: e.g. 8192 x 8192, 320 MiB of raster); exportScale
/// throws ReadoutTooLarge for a larger window and allocates nothing.
constexpr std::uint64_t kMaxReadoutCells = std::uint64_t{1} << 26;
/// Raster cells of a window, exact for any box (no overflow); 0 for an empty box, saturated at
/// UINT64_MAX.
std::uint64_t readoutCells(const CellBox& window);
/// True when exportScale accepts `window` (readoutCells(window) <= kMaxReadoutCells).
inline bool readoutFits(const CellBox& window) { return readoutCells(window) <= kMaxReadoutCells; }

}  // namespace wavog

#endif  // WAVOG_MAPPING_CORE_LIMITS_H_
