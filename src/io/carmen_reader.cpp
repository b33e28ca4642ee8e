// CARMEN log reader. Lines are read through zlib's gz* interface from one descriptor (a file, a
// FIFO or a pipe); zlib reads plain text as it is and says whether the stream was gzip, so that a
// truncated stream can be told apart from the end of a plain file. Numbers are parsed with
// std::from_chars (locale-independent).
#include "wavog_mapping/io/carmen_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <system_error>

namespace wavog {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr long kMaxBeams = 100000;             // sanity bound on a beam count field
constexpr unsigned kGzBufferBytes = 1u << 18;  // zlib's input/output buffers
constexpr std::size_t kLineChunk = 1u << 16;   // gzgets chunk; longer lines are assembled

/// Why one line is malformed; turned into a CarmenParseError with file and line by the reader.
struct LineError {
  std::string reason;
};

/// Walks the space-separated fields of one line, naming each field in its error messages.
class FieldCursor {
 public:
  FieldCursor(std::string_view line, const char* type) : rest_(line), type_(type) {}

  std::string_view word(const char* name) {
    skipSpace();
    if (rest_.empty()) {
      throw LineError{std::string(type_) + ": missing field '" + name + "' (line has only " +
                      std::to_string(fields_) + " fields)"};
    }
    std::size_t end = 0;
    while (end < rest_.size() && !isSpace(rest_[end])) ++end;
    std::string_view token = rest_.substr(0, end);
    rest_.remove_prefix(end);
    ++fields_;
    return token;
  }

  template <typename T>
  T number(const char* name) {
    const std::string_view token = word(name);
    T value{};
    const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
    if (result.ec != std::errc() || result.ptr != token.data() + token.size()) {
      throw LineError{std::string(type_) + ": field '" + name + "' is not a number: '" +
                      std::string(token.substr(0, 32)) + "'"};
    }
    return value;
  }

  long count(const char* name, long min_value) {
    const long n = number<long>(name);
    if (n < min_value || n > kMaxBeams) {
      throw LineError{std::string(type_) + ": field '" + name + "' = " + std::to_string(n) +
                      " is outside [" + std::to_string(min_value) + ", " +
                      std::to_string(kMaxBeams) + "]"};
    }
    return n;
  }

  void expectEnd() {
    skipSpace();
    if (!rest_.empty()) {
      std::size_t extra = 0;
      while (!rest_.empty()) {
        word("extra");
        ++extra;
        skipSpace();
      }
      throw LineError{std::string(type_) + ": " + std::to_string(extra) +
                      " unexpected field(s) after the logger time stamp"};
    }
  }

 private:
  static bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
  void skipSpace() {
    std::size_t i = 0;
    while (i < rest_.size() && isSpace(rest_[i])) ++i;
    rest_.remove_prefix(i);
  }

  std::string_view rest_;
  const char* type_;
  std::size_t fields_ = 1;  // the type field is already consumed
};

Pose2 readPose(FieldCursor* f, const char* x, const char* y, const char* theta) {
  Pose2 p;
  p.x = f->number<double>(x);
  p.y = f->number<double>(y);
  p.theta = f->number<double>(theta);
  return p;
}

void readRanges(FieldCursor* f, long n, std::vector<float>* ranges) {
  ranges->resize(static_cast<std::size_t>(n));
  for (auto& r : *ranges) r = f->number<float>("range");
}

/// FLASER / RLASER: "n r_1..r_n x y theta odom_x odom_y odom_theta ipc_ts host logger_ts".
/// No angle fields: the beams span 180 deg from -pi/2, 1 deg or 0.5 deg apart; a beam count
/// of 181 / 361 (odd) includes the end bearing +pi/2, 180 / 360 (even) stops one step short.
void parseFrontLaser(FieldCursor* f, CarmenScan* scan) {
  const long n = f->count("num_readings", 2);
  readRanges(f, n, &scan->ranges);
  scan->laser_pose = readPose(f, "x", "y", "theta");
  scan->robot_pose = readPose(f, "odom_x", "odom_y", "odom_theta");
  scan->ipc_timestamp = f->number<double>("ipc_timestamp");
  f->word("ipc_hostname");
  scan->logger_timestamp = f->number<double>("logger_timestamp");
  f->expectEnd();
  const long steps = (n % 2 == 1) ? n - 1 : n;
  scan->angle_min = -kPi / 2.0;
  scan->angle_increment = kPi / static_cast<double>(steps);
  scan->range_max = CarmenReader::kNoReturnRange;
}

/// ROBOTLASER1: "type start_angle fov res max_range accuracy remission_mode n r_1..r_n n_rem
/// rem_1..rem_nrem laser_x laser_y laser_theta robot_x robot_y robot_theta tv rv fwd_safety
/// side_safety turn_axis ipc_ts host logger_ts". The fov field is n * res, not the true span,
/// so only start_angle and res define the bearings.
void parseRobotLaser(FieldCursor* f, CarmenScan* scan) {
  f->number<long>("laser_type");
  const double start_angle = f->number<double>("start_angle");
  f->number<double>("fov");
  const double res = f->number<double>("angular_res");
  const double max_range = f->number<double>("max_range");
  f->number<double>("accuracy");
  f->number<long>("remission_mode");
  if (!std::isfinite(start_angle) || !std::isfinite(res) || res == 0.0) {
    throw LineError{"ROBOTLASER1: bad beam geometry (start_angle " + std::to_string(start_angle) +
                    ", angular_res " + std::to_string(res) + ")"};
  }
  const long n = f->count("num_readings", 1);
  readRanges(f, n, &scan->ranges);
  const long n_rem = f->count("num_remissions", 0);
  for (long i = 0; i < n_rem; ++i) f->word("remission");
  scan->laser_pose = readPose(f, "laser_x", "laser_y", "laser_theta");
  scan->robot_pose = readPose(f, "robot_x", "robot_y", "robot_theta");
  f->number<double>("tv");
  f->number<double>("rv");
  f->number<double>("forward_safety_dist");
  f->number<double>("side_safety_dist");
  f->number<double>("turn_axis");
  scan->ipc_timestamp = f->number<double>("ipc_timestamp");
  f->word("ipc_hostname");
  scan->logger_timestamp = f->number<double>("logger_timestamp");
  f->expectEnd();
  scan->angle_min = start_angle;
  scan->angle_increment = res;
  // The sentinels (81.91, ...) lie above 80 m whatever max_range says.
  scan->range_max = (max_range > 0.0 && max_range < CarmenReader::kNoReturnRange)
                        ? max_range
                        : CarmenReader::kNoReturnRange;
}

bool isDirectory(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_directory(p, ec);
}

/// First of start/../shared/data, start/../../shared/data, ... that exists ("" if none).
std::string searchUpwards(const std::filesystem::path& start) {
  std::error_code ec;
  std::filesystem::path dir = std::filesystem::absolute(start, ec);
  if (ec) return "";
  dir = dir.lexically_normal();
  while (true) {
    const std::filesystem::path candidate = dir.parent_path() / "shared" / "data";
    if (isDirectory(candidate)) return candidate.lexically_normal().string();
    if (dir == dir.parent_path() || dir.parent_path().empty()) return "";
    dir = dir.parent_path();
  }
}

}  // namespace

ScanView CarmenScan::view(double range_min) const {
  return ScanView{ranges.data(), ranges.size(), angle_min, angle_increment, range_min, range_max};
}

CarmenParseError::CarmenParseError(const std::string& file, std::size_t line,
                                   const std::string& reason)
    : std::runtime_error(file + ":" + std::to_string(line) + ": " + reason), line_(line) {}

struct CarmenReader::Impl {
  std::string path;
  bool strict = true;
  bool gzip = false;
  gzFile file = nullptr;
  std::size_t line_number = 0;
  std::vector<std::string> errors;
  std::string line;
  std::vector<char> chunk = std::vector<char>(kLineChunk);

  /// Throws if zlib reports an error (truncated or corrupted stream, read error).
  void checkStream() const {
    int errnum = Z_OK;
    const char* message = gzerror(file, &errnum);
    if (errnum == Z_OK) return;
    if (errnum == Z_BUF_ERROR) {
      throw std::runtime_error(path +
                               ": truncated gzip stream (unexpected end of file after line " +
                               std::to_string(line_number) + ")");
    }
    if (errnum == Z_ERRNO) {
      throw std::runtime_error(path + ": read error after line " + std::to_string(line_number) +
                               ": " + std::strerror(errno));
    }
    throw std::runtime_error(path + ": corrupted gzip stream after line " +
                             std::to_string(line_number) + ": " + (message ? message : "?"));
  }

  /// Reads one line into `line` (without the end of line); false at the end of the file.
  bool readLine() {
    line.clear();
    while (true) {
      if (gzgets(file, chunk.data(), static_cast<int>(chunk.size())) == nullptr) {
        checkStream();
        if (line.empty()) return false;
        break;  // last line without an end of line
      }
      const std::size_t len = std::strlen(chunk.data());
      line.append(chunk.data(), len);
      if (len > 0 && chunk[len - 1] == '\n') break;
    }
    // A last line without '\n' may be cut by a truncated stream: check before parsing it.
    if (line.empty() || line.back() != '\n') checkStream();
    ++line_number;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    return true;
  }
};

CarmenReader::CarmenReader(const std::string& path, bool strict) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->strict = strict;
  // One open, so that a pipe or FIFO (`<(zcat log)`) loses no byte to a probe; zlib reads plain
  // text transparently and tells afterwards whether the stream was gzip.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !(S_ISREG(st.st_mode) || S_ISFIFO(st.st_mode))) {
    const bool dir = S_ISDIR(st.st_mode);
    ::close(fd);
    throw std::runtime_error(path + (dir ? ": is a directory, not a CARMEN log"
                                         : ": not a regular file, FIFO or pipe (a device or "
                                           "socket), not a CARMEN log"));
  }
  impl_->file = gzdopen(fd, "rb");
  if (impl_->file == nullptr) {
    ::close(fd);
    throw std::runtime_error(path + ": cannot open: out of memory");
  }
  gzbuffer(impl_->file, kGzBufferBytes);
  impl_->gzip = gzdirect(impl_->file) == 0;
}

CarmenReader::~CarmenReader() {
  if (impl_ && impl_->file != nullptr) gzclose(impl_->file);
}

bool CarmenReader::next(CarmenScan* scan) {
  Impl& d = *impl_;
  while (d.readLine()) {
    std::string_view rest(d.line);
    const std::size_t start = rest.find_first_not_of(" \t");
    if (start == std::string_view::npos || rest[start] == '#') continue;
    rest.remove_prefix(start);
    const std::size_t end = std::min(rest.find_first_of(" \t"), rest.size());
    const std::string_view type = rest.substr(0, end);
    const bool front = (type == "FLASER" || type == "RLASER");
    const bool robot = (type == "ROBOTLASER1");
    if (!front && !robot) continue;
    rest.remove_prefix(end);
    const char* type_name = front ? (type == "FLASER" ? "FLASER" : "RLASER") : "ROBOTLASER1";
    FieldCursor fields(rest, type_name);
    try {
      scan->type = type_name;
      scan->line = d.line_number;
      if (front) {
        parseFrontLaser(&fields, scan);
      } else {
        parseRobotLaser(&fields, scan);
      }
      return true;
    } catch (const LineError& e) {
      CarmenParseError error(d.path, d.line_number, e.reason);
      if (d.strict) throw error;
      d.errors.emplace_back(error.what());
    }
  }
  return false;
}

const std::vector<std::string>& CarmenReader::errors() const { return impl_->errors; }
bool CarmenReader::compressed() const { return impl_->gzip; }
std::size_t CarmenReader::linesRead() const { return impl_->line_number; }

std::vector<CarmenScan> readCarmenLog(const std::string& path, std::size_t max_scans) {
  CarmenReader reader(path, true);
  std::vector<CarmenScan> scans;
  CarmenScan scan;
  while ((max_scans == 0 || scans.size() < max_scans) && reader.next(&scan)) {
    scans.push_back(std::move(scan));
  }
  return scans;
}

std::string findDataDir(const std::string& hint) {
  const char* env = std::getenv("WAVOG_DATA_DIR");
  if (env != nullptr && env[0] != '\0') return env;
  std::error_code ec;
  std::string found = searchUpwards(std::filesystem::current_path(ec));
  if (found.empty() && !hint.empty()) found = searchUpwards(hint);
#ifdef WAVOG_SOURCE_DIR
  if (found.empty()) found = searchUpwards(WAVOG_SOURCE_DIR);
#endif
  return found;
}

}  // namespace wavog
