// libFuzzer harness: the CARMEN log reader on arbitrary text (or gzip bytes), strict and lenient.
// Input: one mode byte (bit 0: strict), then the log. Every scan returned must be one the core
// can take as it is: as many ranges as the view says, a finite non-zero increment, range_max in
// (0, 80], a line number that grows.
#include <cmath>

#include "fuzz_support.h"
#include "wavog_mapping/io/carmen_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const bool strict = (data[0] & 1) != 0;
  static const std::string path = wavog_fuzz::scratchPath("log.carmen");
  wavog_fuzz::writeFile(path, data + 1, size - 1);
  try {
    wavog::CarmenReader reader(path, strict);
    wavog::CarmenScan scan;
    std::size_t last_line = 0, scans = 0;
    while (reader.next(&scan)) {
      ++scans;
      const wavog::ScanView v = scan.view(0.0);
      WAVOG_FUZZ_CHECK(v.count == scan.ranges.size() && v.ranges == scan.ranges.data(),
                       "view of %zu beams over %zu ranges", v.count, scan.ranges.size());
      WAVOG_FUZZ_CHECK(std::isfinite(v.angle_min) && std::isfinite(v.angle_increment) &&
                           v.angle_increment != 0.0,
                       "line %zu: beam geometry %g + i * %g", scan.line, v.angle_min,
                       v.angle_increment);
      WAVOG_FUZZ_CHECK(v.range_max > 0.0 && v.range_max <= wavog::CarmenReader::kNoReturnRange,
                       "line %zu: range_max %g", scan.line, v.range_max);
      WAVOG_FUZZ_CHECK(scan.line > last_line && scan.line <= reader.linesRead(),
                       "line %zu after %zu (%zu read)", scan.line, last_line, reader.linesRead());
      last_line = scan.line;
    }
    WAVOG_FUZZ_CHECK(strict || reader.errors().size() + scans <= reader.linesRead() + 1,
                     "%zu errors and %zu scans from %zu lines", reader.errors().size(), scans,
                     reader.linesRead());
  } catch (const wavog::CarmenParseError& e) {
    WAVOG_FUZZ_CHECK(strict, "lenient mode threw a parse error: %s", e.what());
  } catch (const std::runtime_error&) {
    // An unreadable or corrupted gzip stream: refused with a message, which is the contract.
  }
  return 0;
}
