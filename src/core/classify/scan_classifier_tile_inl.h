// Inline definitions of the ScanClassifier (scan_classifier.h), part 3: the 64 cells of an 8 x 8
// tile by row runs. Inside a narrow square the side of a cell against a sector boundary is linear
// along each row (or column) of cells, so each boundary is located once per row, and the cells
// surely past it (and surely before it) are a run of the row: a count and a mask. The cells of
// one sector are then the cells past its first boundary and before its next; a sector whose
// cells all lie within its beam's E limit (or all beyond its U limit) needs no distance; only the
// others compare their cells' squared distances. A cell too close to a boundary to tell takes the
// per-cell path (table, cross products, the reference's bearing).
#ifndef WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_TILE_INL_H_
#define WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_TILE_INL_H_

#include <array>

#include "classify/scan_classifier.h"

namespace wavog {
namespace detail {

namespace tile {

/// The 8 x 8 bit matrix m (bit x + 8 y) transposed (bit y + 8 x).
inline std::uint64_t transpose(std::uint64_t m) {
  std::uint64_t t = (m ^ (m >> 7)) & 0x00AA00AA00AA00AAull;
  m ^= t ^ (t << 7);
  t = (m ^ (m >> 14)) & 0x0000CCCC0000CCCCull;
  m ^= t ^ (t << 14);
  t = (m ^ (m >> 28)) & 0x00000000F0F0F0F0ull;
  m ^= t ^ (t << 28);
  return m;
}

/// One boundary's crossings of the tile's 8 lines: the cells of each line surely below its
/// crossing (low) and surely above it (high); q0: line 0's crossing, in cells along the line;
/// step: its change per line; margin: the unsure half-width, in cells.
struct Crossings {
  std::uint64_t low, high;
};
#if defined(__SSE2__)
/// The cells p < count[l] of each line l (bit p + 8 l), from 8 counts in 0..8 as int32.
inline std::uint64_t cellsBelow(__m128i counts_lo, __m128i counts_hi) {
  // Each count as the 8 bytes of its line, against the cells' positions 0..7.
  const __m128i bytes =
      _mm_packus_epi16(_mm_packs_epi32(counts_lo, counts_hi), _mm_setzero_si128());
  const __m128i twice = _mm_unpacklo_epi8(bytes, bytes);
  const __m128i lines03 = _mm_unpacklo_epi16(twice, twice),
                lines47 = _mm_unpackhi_epi16(twice, twice);
  const __m128i pos = _mm_set_epi8(7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0);
  const auto bits = [&](__m128i v) {
    return static_cast<std::uint64_t>(_mm_movemask_epi8(_mm_cmpgt_epi8(v, pos)));
  };
  return bits(_mm_unpacklo_epi32(lines03, lines03)) |
         bits(_mm_unpackhi_epi32(lines03, lines03)) << 16 |
         bits(_mm_unpacklo_epi32(lines47, lines47)) << 32 |
         bits(_mm_unpackhi_epi32(lines47, lines47)) << 48;
}
#endif

inline Crossings crossings(double q0, double step, double margin) {
#if defined(__SSE2__)
  const __m128d zero = _mm_setzero_pd(), eight = _mm_set1_pd(8.0);
  const __m128d minus_one = _mm_set1_pd(-1.0), seven = _mm_set1_pd(7.0), one = _mm_set1_pd(1.0);
  const __m128d m = _mm_set1_pd(margin), st = _mm_set1_pd(step), q = _mm_set1_pd(q0);
  __m128i below[2], above[2];
  for (int h = 0; h < 2; ++h) {
    __m128i nb[2], na[2];
    for (int p = 0; p < 2; ++p) {
      const int l = 4 * h + 2 * p;
      const __m128d c = _mm_add_pd(q, _mm_mul_pd(_mm_set_pd(l + 1, l), st));
      // Cells below: ceil(c - margin) clamped to [0, 8], as 8 - trunc(8 - v). maxpd gives its
      // second operand when one is NaN (a boundary parallel to the lines: 0 x inf), so a NaN
      // crossing leaves no cell below and, with the operands swapped, none above.
      const __m128d lo = _mm_min_pd(_mm_max_pd(_mm_sub_pd(c, m), zero), eight);
      nb[p] = _mm_cvttpd_epi32(_mm_sub_pd(eight, lo));
      // The first cell above: floor(c + margin) + 1 clamped to [0, 8], as trunc(v + 1).
      const __m128d hi = _mm_min_pd(_mm_max_pd(minus_one, _mm_add_pd(c, m)), seven);
      na[p] = _mm_cvttpd_epi32(_mm_add_pd(hi, one));
    }
    below[h] = _mm_sub_epi32(_mm_set1_epi32(8), _mm_unpacklo_epi64(nb[0], nb[1]));
    above[h] = _mm_unpacklo_epi64(na[0], na[1]);
  }
  const std::uint64_t low = cellsBelow(below[0], below[1]);
  // No cell within the margin (the rule): every cell not below is above.
  const int same = _mm_movemask_epi8(
      _mm_and_si128(_mm_cmpeq_epi32(below[0], above[0]), _mm_cmpeq_epi32(below[1], above[1])));
  if (same == 0xFFFF) return {low, ~low};
  return {low, ~cellsBelow(above[0], above[1])};
#else
  Crossings x{0, 0};
  for (unsigned l = 0; l < 8; ++l) {
    const double c = q0 + static_cast<double>(l) * step;
    if (std::isnan(c)) continue;  // no cell surely on either side
    const double lo = std::min(std::max(c - margin, 0.0), 8.0);
    const auto below = static_cast<unsigned>(8 - static_cast<std::int32_t>(8.0 - lo));
    const auto above = static_cast<unsigned>(std::min(std::max(c + margin, -1.0), 7.0) + 1.0);
    x.low |= ((std::uint64_t{1} << below) - 1) << (8 * l);
    x.high |= (std::uint64_t{0xFF} ^ ((std::uint64_t{1} << above) - 1)) << (8 * l);
  }
  return x;
#endif
}

}  // namespace tile

inline bool ScanClassifier::classifyTile(std::int64_t ix0, std::int64_t iy0, const SquareInfo& box,
                                         TileMasks* out) const {
  // The reference's arithmetic for the cells' offsets and squared distances.
  const double x0 = static_cast<double>(ix0), y0 = static_cast<double>(iy0);
  std::array<double, 8> dx, dy, dx2, dy2;
  for (std::size_t i = 0; i < 8; ++i) {
    const double half = static_cast<double>(i) + 0.5;
    dx[i] = (x0 + half) * s_.res - s_.px;
    dy[i] = (y0 + half) * s_.res - s_.py;
    dx2[i] = dx[i] * dx[i];
    dy2[i] = dy[i] * dy[i];
  }
  // The hit cells of the square's beams (O whatever else).
  std::uint64_t hit = 0;
  for (int j = box.jlo; j <= box.jhi; ++j) {
    const auto ju = static_cast<std::size_t>(j);
    const auto ux = static_cast<std::uint64_t>(s_.hit_x[ju] - ix0);
    const auto uy = static_cast<std::uint64_t>(s_.hit_y[ju] - iy0);
    const bool in = s_.kind[ju] == BeamKind::kHit && ux < 8 && uy < 8;
    hit |= static_cast<std::uint64_t>(in) << ((ux + 8 * uy) & 63u);
  }
  // The least and greatest squared distance of the tile's cells.
  const TileRange d2r{
      *std::min_element(dx2.begin(), dx2.end()) + *std::min_element(dy2.begin(), dy2.end()),
      std::max(dx2[0], dx2[7]) + std::max(dy2[0], dy2[7])};
  TileMasks m;
  // Runs of sectors: neighbours whose cells are all E over the tile (each within its beam's E
  // limit) merge, as do those all U (beyond both limits, or outside the fan); a sector of mixed
  // cells is a run of its own. Only the boundaries between runs are located.
  std::array<int, kFewSectors + 1> first;  // run r: sectors first[r] .. first[r + 1] - 1
  std::array<SectorKind, kFewSectors + 1> kind;
  int runs = 0;
  const int lo = box.single ? box.jlo : box.slo, hi = box.single ? box.jlo : box.shi;
  for (int j = lo; j <= hi; ++j) {
    const SectorKind k = sectorKind(j, d2r);
    if (runs > 0 && k != SectorKind::kMixed && k == kind[static_cast<std::size_t>(runs - 1)]) {
      continue;
    }
    first[static_cast<std::size_t>(runs)] = j;
    kind[static_cast<std::size_t>(runs)] = k;
    ++runs;
  }
  if (runs - 1 > kTileMaxBoundaries) return false;
  const auto apply = [&](int r, std::uint64_t cells, const double* a2, const double* l2) {
    const auto ru = static_cast<std::size_t>(r);
    if (kind[ru] == SectorKind::kEmpty) m.e |= cells;
    if (kind[ru] == SectorKind::kMixed) classifySector(first[ru], cells, a2, l2, d2r, &m);
  };
  if (runs == 1) {
    apply(0, ~std::uint64_t{0}, dx2.data(), dy2.data());
  } else {
    // Lines are rows (cells along x) when the boundaries are nearer the y axis, else columns
    // (transposed: bit y + 8 x until the end). A boundary (bx, by) has the cells with cross
    // product bx dy - by dx > 0 past it; along a line that product is linear, and zero at the
    // crossing q (cells along the line from cell 0's centre).
    const auto mid = static_cast<std::size_t>(box.slo + 1 + (box.shi - box.slo - 1) / 2);
    const bool rows = std::fabs(s_.bnd_y[mid]) >= std::fabs(s_.bnd_x[mid]);
    const double u0 = rows ? dx[0] : dy[0], v0 = rows ? dy[0] : dx[0];
    // Sure decisions need |cross| above twice the side tests' own margin over the tile plus the
    // rounding of the idealised cell positions (dx0 + i res) the crossings assume.
    const double t = 2.0 * kRayMargin *
                         (std::max(std::fabs(dx[0]), std::fabs(dx[7])) +
                          std::max(std::fabs(dy[0]), std::fabs(dy[7]))) +
                     1e-14 * (std::fabs(x0 * s_.res) + std::fabs(y0 * s_.res) + std::fabs(s_.px) +
                              std::fabs(s_.py) + 16.0 * s_.res);
    const double inv_res = 1.0 / s_.res, t_cells = t * inv_res;
    // Run r + 1's first boundary: past[r]; run r's sure cells are past its own and not past[r].
    std::array<std::uint64_t, kFewSectors + 1> past;
    std::uint64_t unsure = 0;
    for (int i = 0; i + 1 < runs; ++i) {
      const auto k = static_cast<std::size_t>(first[static_cast<std::size_t>(i + 1)]);
      // Rows: cross = bx (v0 + line res) - by (u0 + q res); columns: by and bx swap roles and
      // the product changes sign.
      const double a = rows ? s_.bnd_y[k] : s_.bnd_x[k], b = rows ? s_.bnd_x[k] : s_.bnd_y[k];
      const double inv_a = 1.0 / a, step = b * inv_a;
      const tile::Crossings x =
          tile::crossings((v0 * step - u0) * inv_res, step, t_cells * std::fabs(inv_a));
      // Below the crossing the product has a's sign (rows), or the opposite (columns).
      const bool low_past = (a > 0) == rows;
      past[static_cast<std::size_t>(i)] = low_past ? x.low : x.high;
      unsure |= ~(x.low | x.high);
    }
    const double* l2 = rows ? dy2.data() : dx2.data();  // by line
    const double* c2 = rows ? dx2.data() : dy2.data();  // along it
    std::uint64_t past_prev = ~unsure;
    for (int i = 0; i + 1 < runs; ++i) {
      const std::uint64_t p = past[static_cast<std::size_t>(i)];
      apply(i, past_prev & ~p, c2, l2);
      past_prev = p & ~unsure;
    }
    apply(runs - 1, past_prev, c2, l2);
    if (!rows) {
      m.e = tile::transpose(m.e);
      m.o = tile::transpose(m.o);
      unsure = tile::transpose(unsure);
    }
    // Cells near a boundary: the per-cell path.
    for (std::uint64_t c = unsure & ~hit; c != 0; c &= c - 1) {
      const auto bit = static_cast<unsigned>(__builtin_ctzll(c));
      const double cdx = dx[bit & 7u], cdy = dy[bit >> 3];
      long j = s_.tableSector(cdx, cdy);
      if (j < 0) j = sectorIn(cdx, cdy, box, box.slo);
      if (j < 0 || j >= s_.n) continue;
      const CellClass cls = cellAt(static_cast<std::size_t>(j), cdx * cdx + cdy * cdy);
      const std::uint64_t one = std::uint64_t{1} << bit;
      if (cls == CellClass::kEmpty) m.e |= one;
      if (cls == CellClass::kOccupied) m.o |= one;
    }
  }
  out->e = m.e & ~hit;
  out->o = (m.o & ~out->e) | hit;
  return true;
}

/// How sector j's cells of a tile whose squared distances lie in d2r compare with its limits.
inline ScanClassifier::SectorKind ScanClassifier::sectorKind(int j, const TileRange& d2r) const {
  if (j < 0 || j >= s_.n) return SectorKind::kUnknown;
  const LeafTest& t = s_.leaf[static_cast<std::size_t>(j)];
  if (d2r.hi < t.e) return SectorKind::kEmpty;
  if (d2r.lo >= t.e && d2r.lo > t.o) return SectorKind::kUnknown;
  return SectorKind::kMixed;
}

/// Sector j's cells `cells` of a tile (bit along + 8 line; squared offsets along the line a2 and
/// of the line l2; the tile's cells within [d2.lo, d2.hi]): E within its beam's E limit, O within
/// its U limit (a hit beam), else U. A sector whose cells all lie on one side of both limits
/// compares no distance.
inline void ScanClassifier::classifySector(int j, std::uint64_t cells, const double* a2,
                                           const double* l2, const TileRange& d2r,
                                           TileMasks* m) const {
  if (cells == 0 || j < 0 || j >= s_.n) return;
  const LeafTest& t = s_.leaf[static_cast<std::size_t>(j)];
  if (d2r.hi < t.e) {
    m->e |= cells;
    return;
  }
  if (d2r.lo >= t.e && d2r.lo > t.o) return;
  for (std::uint64_t c = cells; c != 0; c &= c - 1) {
    const auto bit = static_cast<unsigned>(__builtin_ctzll(c));
    const double d2 = a2[bit & 7u] + l2[bit >> 3];
    const std::uint64_t one = std::uint64_t{1} << bit;
    m->e |= d2 < t.e ? one : 0;
    m->o |= (d2 >= t.e && d2 <= t.o) ? one : 0;
  }
}

}  // namespace detail
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_CORE_CLASSIFY_SCAN_CLASSIFIER_TILE_INL_H_
