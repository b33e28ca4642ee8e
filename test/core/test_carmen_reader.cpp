// Tests of the CARMEN log reader: the two shared logs (FLASER, ROBOTLASER1, gzip), synthetic
// logs for every line type, malformed lines (strict and lenient), truncated and corrupted gzip,
// missing files and the data directory search. Uses gtest and wavog_io only.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "synthetic_log.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

std::string dataFile(const std::string& name) {
  const std::string dir = wavog::findDataDir(WAVOG_SOURCE_DIR);
  if (dir.empty()) return "";
  return (fs::path(dir) / name).string();
}

/// A fresh temporary directory per test, removed at the end.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("wavog_carmen_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name, const std::string& content) const {
    const std::string p = (path_ / name).string();
    std::ofstream out(p, std::ios::binary);
    out << content;
    return p;
  }
  std::string path(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// CRC-32 (IEEE, as gzip uses), bitwise: only for the small test files.
std::uint32_t crc32(const std::string& data) {
  std::uint32_t crc = 0xffffffffu;
  for (unsigned char c : data) {
    crc ^= c;
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void putLe32(std::string* out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}

/// A valid gzip file of `data` with one stored (uncompressed) deflate block (data < 64 KiB).
std::string gzipStored(const std::string& data) {
  std::string out = {'\x1f', '\x8b', '\x08', '\0', '\0', '\0', '\0', '\0', '\0', '\x03'};
  out.push_back('\x01');  // final block, stored
  const auto len = static_cast<std::uint16_t>(data.size());
  const auto nlen = static_cast<std::uint16_t>(~len);
  out.push_back(static_cast<char>(len & 0xff));
  out.push_back(static_cast<char>(len >> 8));
  out.push_back(static_cast<char>(nlen & 0xff));
  out.push_back(static_cast<char>(nlen >> 8));
  out += data;
  putLe32(&out, crc32(data));
  putLe32(&out, static_cast<std::uint32_t>(data.size()));
  return out;
}

std::string ranges(int n, const std::string& value) {
  std::string s;
  for (int i = 0; i < n; ++i) s += value + " ";
  return s;
}

/// A well-formed FLASER line with n beams, all reading `value`.
std::string flaser(int n, const std::string& value, double t, const char* type = "FLASER") {
  std::ostringstream s;
  s << type << " " << n << " " << ranges(n, value) << "1.5 -2.25 0.5 1.0 2.0 0.25 " << t << " host "
    << t + 0.001;
  return s.str();
}

/// A well-formed ROBOTLASER1 line: 4 beams from -0.5 rad, 0.25 rad apart, 2 remissions.
std::string robotLaser(double t) {
  std::ostringstream s;
  s << "ROBOTLASER1 0 -0.5 1.0 0.25 50.0 0.01 0 4 1.0 2.0 81.91 3.0 2 0.5 0.6 "
    << "3.0 4.0 1.0 2.5 3.5 0.75 0.1 0.2 0.3 0.4 0.5 " << t << " b21 " << t - 100.0;
  return s.str();
}

std::string catchMessage(const std::string& path, bool strict, std::size_t* line = nullptr) {
  try {
    wavog::CarmenReader reader(path, strict);
    wavog::CarmenScan scan;
    while (reader.next(&scan)) {
    }
  } catch (const wavog::CarmenParseError& e) {
    if (line != nullptr) *line = e.line();
    return e.what();
  } catch (const std::runtime_error& e) {
    return std::string("runtime_error: ") + e.what();
  }
  return "";
}

TEST(CarmenReader, RealDataReadsFr079FlaserScans) {
  const std::string path = dataFile("fr079-corrected.log.gz");
  ASSERT_FALSE(path.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  wavog::CarmenReader reader(path);
  EXPECT_TRUE(reader.compressed());
  wavog::CarmenScan scan;
  std::size_t count = 0;
  std::size_t no_return = 0;
  double last_stamp = -1.0;
  while (reader.next(&scan)) {
    if (count == 0) {
      EXPECT_EQ(scan.type, "FLASER");
      EXPECT_NEAR(scan.ipc_timestamp, 0.227623, 1e-9);
      EXPECT_NEAR(scan.logger_timestamp, 0.227623, 1e-9);
      EXPECT_NEAR(scan.laser_pose.x, 0.00123601, 1e-12);
      EXPECT_NEAR(scan.laser_pose.y, -0.00106807, 1e-12);
      EXPECT_NEAR(scan.laser_pose.theta, 2.85e-05, 1e-12);
      EXPECT_GT(scan.line, 100u);  // after the PARAM header
    }
    ASSERT_EQ(scan.type, "FLASER");
    ASSERT_EQ(scan.ranges.size(), 360u);
    ASSERT_DOUBLE_EQ(scan.angle_min, -kPi / 2);
    ASSERT_NEAR(scan.angle_increment, 0.5 * kDeg, 1e-15);
    ASSERT_DOUBLE_EQ(scan.range_max, 80.0);
    EXPECT_GE(scan.ipc_timestamp, last_stamp);
    last_stamp = scan.ipc_timestamp;
    for (float r : scan.ranges) no_return += scan.isNoReturn(r) ? 1 : 0;
    ++count;
  }
  EXPECT_EQ(count, 4791u);
  EXPECT_EQ(no_return, 36004u);  // every 81.91 sentinel, nothing else
  EXPECT_TRUE(reader.errors().empty());
  const wavog::ScanView v = scan.view(0.1);
  EXPECT_EQ(v.count, 360u);
  EXPECT_EQ(v.ranges, scan.ranges.data());
  EXPECT_DOUBLE_EQ(v.range_min, 0.1);
  EXPECT_DOUBLE_EQ(v.range_max, 80.0);
}

TEST(CarmenReader, RealDataReadsCsailRobotLaser1Scans) {
  const std::string path = dataFile("csail-robotlaser1.log.gz");
  ASSERT_FALSE(path.empty()) << "shared data not found: set WAVOG_DATA_DIR";
  const std::vector<wavog::CarmenScan> scans = wavog::readCarmenLog(path);
  ASSERT_EQ(scans.size(), 686u);
  for (const auto& s : scans) {
    ASSERT_EQ(s.type, "ROBOTLASER1");
    ASSERT_EQ(s.ranges.size(), 361u);
    ASSERT_DOUBLE_EQ(s.angle_min, -1.570796);
    ASSERT_DOUBLE_EQ(s.angle_increment, 0.008727);
    ASSERT_DOUBLE_EQ(s.range_max, 80.0);
  }
  EXPECT_NEAR(scans[0].ipc_timestamp, 1134864642.914187, 1e-6);
  EXPECT_NEAR(scans[0].logger_timestamp, 0.430003, 1e-9);
  EXPECT_NEAR(scans[1].laser_pose.x, 0.319678, 1e-12);
  EXPECT_NEAR(scans[1].laser_pose.y, 0.110037, 1e-12);
  EXPECT_NEAR(scans[1].laser_pose.theta, 0.994330, 1e-12);
  EXPECT_NEAR(scans[1].robot_pose.theta, 0.994330, 1e-12);
  EXPECT_TRUE(scans[0].isNoReturn(scans[0].ranges[0]));  // 81.91
  EXPECT_EQ(wavog::readCarmenLog(path, 10).size(), 10u);
}

TEST(CarmenReader, ParsesEveryLineTypeAndSkipsOthers) {
  TempDir tmp;
  std::string log = "# a comment\n";
  log += "PARAM robot_front_laser_max 80.99 1.0 host 1.0\n";
  log += flaser(181, "2.5", 10.0) + "\n";
  log += "ODOM 1 2 3 0 0 0 10.05 host 10.05\n\n   \n";
  log += flaser(360, "81.91", 10.1, "RLASER") + "\r\n";  // CRLF
  log += "NEFF 10\n";
  log += robotLaser(10.2);  // last line without an end of line
  const std::string path = tmp.file("all.log", log);
  wavog::CarmenReader reader(path);
  EXPECT_FALSE(reader.compressed());
  wavog::CarmenScan s;

  ASSERT_TRUE(reader.next(&s));
  EXPECT_EQ(s.type, "FLASER");
  EXPECT_EQ(s.line, 3u);
  ASSERT_EQ(s.ranges.size(), 181u);
  EXPECT_FLOAT_EQ(s.ranges[17], 2.5f);
  EXPECT_DOUBLE_EQ(s.angle_min, -kPi / 2);
  EXPECT_NEAR(s.angle_min + 180 * s.angle_increment, kPi / 2, 1e-12);  // 181 beams end at +pi/2
  EXPECT_DOUBLE_EQ(s.laser_pose.x, 1.5);
  EXPECT_DOUBLE_EQ(s.laser_pose.y, -2.25);
  EXPECT_DOUBLE_EQ(s.laser_pose.theta, 0.5);
  EXPECT_DOUBLE_EQ(s.robot_pose.x, 1.0);
  EXPECT_DOUBLE_EQ(s.robot_pose.y, 2.0);
  EXPECT_DOUBLE_EQ(s.robot_pose.theta, 0.25);
  EXPECT_DOUBLE_EQ(s.ipc_timestamp, 10.0);
  EXPECT_DOUBLE_EQ(s.logger_timestamp, 10.001);

  ASSERT_TRUE(reader.next(&s));
  EXPECT_EQ(s.type, "RLASER");
  EXPECT_EQ(s.line, 7u);
  ASSERT_EQ(s.ranges.size(), 360u);
  EXPECT_NEAR(s.angle_increment, 0.5 * kDeg, 1e-15);  // 360 beams stop one step short
  EXPECT_TRUE(s.isNoReturn(s.ranges[0]));
  EXPECT_FALSE(s.isNoReturn(79.9f));
  EXPECT_TRUE(s.isNoReturn(std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(s.isNoReturn(std::numeric_limits<float>::quiet_NaN()));

  ASSERT_TRUE(reader.next(&s));
  EXPECT_EQ(s.type, "ROBOTLASER1");
  EXPECT_EQ(s.line, 9u);
  ASSERT_EQ(s.ranges.size(), 4u);  // remissions skipped by their count
  EXPECT_FLOAT_EQ(s.ranges[3], 3.0f);
  EXPECT_DOUBLE_EQ(s.angle_min, -0.5);
  EXPECT_DOUBLE_EQ(s.angle_increment, 0.25);
  EXPECT_DOUBLE_EQ(s.range_max, 50.0);
  EXPECT_TRUE(s.isNoReturn(s.ranges[2]));
  EXPECT_DOUBLE_EQ(s.laser_pose.x, 3.0);
  EXPECT_DOUBLE_EQ(s.laser_pose.theta, 1.0);
  EXPECT_DOUBLE_EQ(s.robot_pose.x, 2.5);
  EXPECT_DOUBLE_EQ(s.robot_pose.theta, 0.75);
  EXPECT_DOUBLE_EQ(s.ipc_timestamp, 10.2);
  EXPECT_DOUBLE_EQ(s.logger_timestamp, 10.2 - 100.0);

  EXPECT_FALSE(reader.next(&s));
  EXPECT_FALSE(reader.next(&s));
  EXPECT_EQ(reader.linesRead(), 9u);
}

TEST(CarmenReader, ReadsGzipDetectedByMagicWhateverTheName) {
  TempDir tmp;
  const std::string log = flaser(180, "3.0", 1.0) + "\n" + robotLaser(2.0) + "\n";
  const std::string path = tmp.file("compressed.log", gzipStored(log));  // no .gz suffix
  wavog::CarmenReader reader(path);
  EXPECT_TRUE(reader.compressed());
  wavog::CarmenScan s;
  ASSERT_TRUE(reader.next(&s));
  EXPECT_EQ(s.ranges.size(), 180u);
  EXPECT_NEAR(s.angle_increment, kDeg, 1e-15);
  ASSERT_TRUE(reader.next(&s));
  EXPECT_EQ(s.type, "ROBOTLASER1");
  EXPECT_FALSE(reader.next(&s));
}

// Streams `content` into a new FIFO at `path` from a thread (the writer blocks until the reader
// opens it).
class FifoWriter {
 public:
  FifoWriter(const std::string& path, std::string content) {
    if (::mkfifo(path.c_str(), 0600) != 0) throw std::runtime_error("mkfifo " + path);
    writer_ = std::thread([path, content = std::move(content)] {
      std::ofstream out(path, std::ios::binary);
      out << content;
    });
  }
  ~FifoWriter() { writer_.join(); }

 private:
  std::thread writer_;
};

TEST(CarmenReader, ReadsPlainAndGzipLogsFromAFifoWithoutLosingBytes) {
  TempDir tmp;
  // The first bytes are those a magic-number probe would have taken from the stream.
  const std::string log =
      flaser(181, "2.5", 10.0) + "\n" + robotLaser(11.0) + "\n" + flaser(90, "1.5", 12.0) + "\n";
  for (const bool gz : {false, true}) {
    SCOPED_TRACE(gz ? "gzip" : "plain");
    const std::string path = tmp.path(gz ? "fifo_gz" : "fifo_plain");
    FifoWriter writer(path, gz ? gzipStored(log) : log);
    wavog::CarmenReader reader(path);
    EXPECT_EQ(reader.compressed(), gz);
    wavog::CarmenScan s;
    ASSERT_TRUE(reader.next(&s));
    EXPECT_EQ(s.type, "FLASER");
    EXPECT_EQ(s.ranges.size(), 181u);
    EXPECT_DOUBLE_EQ(s.ipc_timestamp, 10.0);
    ASSERT_TRUE(reader.next(&s));
    EXPECT_EQ(s.type, "ROBOTLASER1");
    ASSERT_TRUE(reader.next(&s));
    EXPECT_EQ(s.ranges.size(), 90u);
    EXPECT_FALSE(reader.next(&s));
  }
}

TEST(CarmenReader, RefusesDevicesAtOnce) {
  for (const char* device : {"/dev/zero", "/dev/null"}) {
    try {
      wavog::CarmenReader reader(device);
      FAIL() << device << ": no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("not a regular file, FIFO or pipe"), std::string::npos)
          << e.what();
    }
  }
}

TEST(CarmenReader, MalformedLinesNameFileAndLine) {
  TempDir tmp;
  const std::string good = flaser(180, "1.0", 1.0);
  struct Case {
    std::string line;
    std::string reason;  // expected part of the message
  };
  const std::vector<Case> cases = {
      {flaser(180, "1.0", 1.0).replace(11, 3, "x.y"), "field 'range' is not a number: 'x.y'"},
      {"FLASER 180 1.0 2.0", "missing field 'range'"},
      {"FLASER abc", "field 'num_readings' is not a number"},
      {"FLASER 1 2.0 0 0 0 0 0 0 1.0 host 1.0", "'num_readings' = 1 is outside"},
      {"FLASER -5", "'num_readings' = -5 is outside"},
      {good + " 7 8", "2 unexpected field(s)"},
      {good.substr(0, good.size() - 11), "missing field"},
      {"ROBOTLASER1 0 -0.5 1.0 0 50 0.01 0 4 1 2 3 4 0 0 0 0 0 0 0 0 0 0 0 0 1 h 1",
       "ROBOTLASER1: bad beam geometry"},
      {"ROBOTLASER1 0 -0.5 1.0 0.25 50 0.01 0 4 1 2 3 4 9 0.1", "missing field 'remission'"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string path = tmp.file("bad" + std::to_string(i) + ".log",
                                      good + "\n# c\n" + cases[i].line + "\n" + good);
    std::size_t line = 0;
    const std::string msg = catchMessage(path, true, &line);
    EXPECT_EQ(msg.rfind(path + ":3: ", 0), 0u) << "case " << i << ": " << msg;
    EXPECT_NE(msg.find(cases[i].reason), std::string::npos) << "case " << i << ": " << msg;
    EXPECT_EQ(line, 3u);
  }
}

TEST(CarmenReader, LenientModeSkipsAndRecordsMalformedLines) {
  TempDir tmp;
  const std::string log = flaser(180, "1.0", 1.0) + "\nFLASER 180 oops\n" +
                          flaser(180, "2.0", 2.0) + "\nROBOTLASER1 0\n" + flaser(180, "3.0", 3.0) +
                          "\n";
  const std::string path = tmp.file("lenient.log", log);
  wavog::CarmenReader reader(path, false);
  std::vector<float> first_ranges;
  wavog::CarmenScan s;
  while (reader.next(&s)) first_ranges.push_back(s.ranges[0]);
  EXPECT_EQ(first_ranges, (std::vector<float>{1.0f, 2.0f, 3.0f}));
  ASSERT_EQ(reader.errors().size(), 2u);
  EXPECT_EQ(reader.errors()[0].rfind(path + ":2: FLASER: ", 0), 0u) << reader.errors()[0];
  EXPECT_EQ(reader.errors()[1].rfind(path + ":4: ROBOTLASER1: ", 0), 0u) << reader.errors()[1];
  EXPECT_THROW(wavog::readCarmenLog(path), wavog::CarmenParseError);  // strict by default
}

TEST(CarmenReader, TruncatedGzipIsAClearError) {
  TempDir tmp;
  const std::string bytes = wavog_test::gzipDeflate(wavog_test::syntheticFlaserLog(400));
  ASSERT_GT(bytes.size(), 100000u);
  const std::string path = tmp.file("cut.log.gz", bytes.substr(0, bytes.size() / 2));
  const std::string msg = catchMessage(path, false);
  EXPECT_NE(msg.find("runtime_error: " + path + ": truncated gzip stream"), std::string::npos)
      << msg;

  // Cut inside the 8-byte trailer: every line is complete, the stream still is not.
  const std::string small = gzipStored(flaser(180, "1.0", 1.0) + "\n");
  const std::string trailer_cut = tmp.file("trailer.log.gz", small.substr(0, small.size() - 3));
  EXPECT_NE(catchMessage(trailer_cut, true).find("truncated gzip stream"), std::string::npos);

  // Corrupted payload (the stored block length no longer matches its complement).
  std::string corrupt = small;
  corrupt[12] = static_cast<char>(corrupt[12] ^ 0x55);
  const std::string bad = tmp.file("corrupt.log.gz", corrupt);
  const std::string bad_msg = catchMessage(bad, true);
  EXPECT_NE(bad_msg.find("runtime_error: " + bad + ": corrupted gzip stream"), std::string::npos)
      << bad_msg;
}

TEST(CarmenReader, MissingFileIsAClearError) {
  TempDir tmp;
  const std::string missing = tmp.path("nope.log");
  try {
    wavog::CarmenReader reader(missing);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing + ": cannot open"), std::string::npos) << e.what();
  }
  EXPECT_THROW(wavog::CarmenReader(tmp.path("")), std::runtime_error);  // a directory
  wavog::CarmenReader empty(tmp.file("empty.log", ""));
  wavog::CarmenScan s;
  EXPECT_FALSE(empty.next(&s));
}

TEST(FindDataDir, EnvironmentFirstThenUpwardsFromHint) {
  const char* old = std::getenv("WAVOG_DATA_DIR");
  const std::string saved = old ? old : "";
  ::setenv("WAVOG_DATA_DIR", "/some/where", 1);
  EXPECT_EQ(wavog::findDataDir(), "/some/where");
  ::unsetenv("WAVOG_DATA_DIR");

  TempDir tmp;
  const fs::path root = tmp.path("root");
  fs::create_directories(root / "shared" / "data");
  fs::create_directories(root / "repo" / "a" / "b");
  const fs::path cwd = fs::current_path();
  fs::current_path("/");  // nothing upwards from /
  EXPECT_EQ(fs::path(wavog::findDataDir((root / "repo" / "a" / "b").string())),
            (root / "shared" / "data"));
  fs::current_path(cwd);
  if (old != nullptr) ::setenv("WAVOG_DATA_DIR", saved.c_str(), 1);
}

}  // namespace
