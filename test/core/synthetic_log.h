// Test input made in the test itself: a CARMEN log of a laser driving through a room, plain text or
// gzip (zlib's deflate, as real logs are), for the tests whose subject is not the real data (a
// truncated stream, the tools' errors). Header-only; the tests that use it link zlib.
#ifndef WAVOG_MAPPING_TEST_CORE_SYNTHETIC_LOG_H_
#define WAVOG_MAPPING_TEST_CORE_SYNTHETIC_LOG_H_

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace wavog_test {

/// `scans` FLASER lines (180 beams, 1 deg from -90 deg) of a laser moving along x at 0.5 m/s in a
/// 20 m x 8 m room, 10 Hz, with a small deterministic noise on each range so that the text does
/// not compress to nothing (about 2.6 : 1 with deflate, like fr079).
inline std::string syntheticFlaserLog(int scans) {
  std::string log = "# synthetic log: a laser driving along x in a 20 m x 8 m room\n";
  unsigned noise = 12345u;
  char buf[64];
  for (int k = 0; k < scans; ++k) {
    const double t = 0.1 * k;
    const double x = -8.0 + std::fmod(0.05 * k, 16.0);
    log += "FLASER 180 ";
    for (int i = 0; i < 180; ++i) {
      const double a = (-90.0 + i) * M_PI / 180.0;
      const double c = std::cos(a);
      const double s = std::sin(a);
      double r = 50.0;  // the room's walls: x in [-10, 10], y in [-4, 4]
      if (c > 1e-9) r = std::min(r, (10.0 - x) / c);
      if (s > 1e-9) r = std::min(r, 4.0 / s);
      if (s < -1e-9) r = std::min(r, -4.0 / s);
      noise = noise * 1103515245u + 12345u;
      r += ((noise >> 16) % 21 - 10) * 0.002;
      std::snprintf(buf, sizeof buf, "%.3f ", r);
      log += buf;
    }
    std::snprintf(buf, sizeof buf, "%.3f 0.000 0.000 %.3f 0.000 0.000 ", x, x);
    log += buf;
    std::snprintf(buf, sizeof buf, "%.3f synth %.3f\n", t, t);
    log += buf;
  }
  return log;
}

/// `text` as a gzip file (deflate, default level).
inline std::string gzipDeflate(const std::string& text) {
  z_stream z{};
  if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw std::runtime_error("deflateInit2 failed");
  }
  std::string out(deflateBound(&z, static_cast<uLong>(text.size())), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  z.avail_in = static_cast<uInt>(text.size());
  z.next_out = reinterpret_cast<Bytef*>(&out[0]);
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("deflate did not finish");
  return out;
}

}  // namespace wavog_test

#endif  // WAVOG_MAPPING_TEST_CORE_SYNTHETIC_LOG_H_
