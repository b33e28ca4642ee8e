// Save / load: exact round trip; truncated, corrupted, foreign and mismatched files rejected with
// the map left unchanged; no symlink followed on save; regular files only, size bound by the header.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iterator>
#include <type_traits>

#include "map_access.h"
#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::MapIoError;
using wavog::MapParams;
using wavog::WaveletMap;

// Per process, so that two builds running this test at once do not share files.
std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "wavog_io_" + std::to_string(::getpid()) + "_" + name;
}

std::vector<char> readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
/// Appends the file's CRC-32 of `bytes` (a map file without its last 4 bytes).
void appendCrc(std::vector<char>* bytes) {
  const auto crc = static_cast<std::uint32_t>(::crc32(
      0L, reinterpret_cast<const Bytef*>(bytes->data()), static_cast<uInt>(bytes->size())));
  const auto* c = reinterpret_cast<const char*>(&crc);
  bytes->insert(bytes->end(), c, c + sizeof(crc));
}

void writeAll(const std::string& path, const std::vector<char>& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

MapParams params() {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kForget);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 5;
  return p;
}

void fill(WaveletMap* map, std::uint32_t seed) {
  RandomScans scans(seed, 12.0);
  for (int i = 0; i < 40; ++i) {
    const auto s = scans.next();
    map->integrate(s.pose, s.view());
  }
}

void expectSameMap(const WaveletMap& a, const WaveletMap& b) {
  for (std::int64_t y = -70; y < 70; ++y)
    for (std::int64_t x = -70; x < 70; ++x) {
      ASSERT_FLOAT_EQ(a.value({x, y}), b.value({x, y})) << x << "," << y;
      ASSERT_EQ(a.isObserved({x, y}), b.isObserved({x, y}));
    }
}

TEST(MapIo, RoundTripIsExact) {
  WaveletMap map(params());
  fill(&map, 5);
  const std::string path = tempPath("roundtrip.wavog");
  map.save(path);
  WaveletMap loaded(params());
  loaded.load(path);
  expectSameMap(map, loaded);
  EXPECT_EQ(loaded.stats().nodes, map.stats().nodes);
  EXPECT_EQ(loaded.stats().blocks, map.stats().blocks);
  // Loaded maps keep integrating like the original.
  RandomScans more(99, 12.0);
  for (int i = 0; i < 10; ++i) {
    const auto s = more.next();
    map.integrate(s.pose, s.view());
    loaded.integrate(s.pose, s.view());
  }
  for (std::int64_t y = -70; y < 70; y += 3)
    for (std::int64_t x = -70; x < 70; x += 3) EXPECT_NEAR(map.value({x, y}), loaded.value({x, y}), 1e-5);
  std::remove(path.c_str());
}

TEST(MapIo, BadFilesAreRejectedAndTheMapIsUnchanged) {
  WaveletMap source(params());
  fill(&source, 6);
  const std::string good = tempPath("good.wavog");
  source.save(good);
  const auto bytes = readAll(good);
  ASSERT_GT(bytes.size(), 100u);

  WaveletMap target(params());
  fill(&target, 7);
  WaveletMap copy(params());
  fill(&copy, 7);

  struct Case {
    std::string name;
    std::vector<char> data;
    std::string expect;
  };
  std::vector<Case> cases;
  cases.push_back({"truncated", std::vector<char>(bytes.begin(), bytes.begin() + static_cast<long>(bytes.size() / 2)), "checksum"});
  auto flipped = bytes;
  flipped[bytes.size() / 3] = static_cast<char>(flipped[bytes.size() / 3] ^ 0x10);
  cases.push_back({"bit flip", flipped, "checksum"});
  cases.push_back({"foreign", std::vector<char>{'P', '5', '\n', '1', ' ', '1', '\n', '2', '5', '5', '\n', 0}, "bad magic"});
  cases.push_back({"empty", {}, "bad magic"});
  auto version = bytes;
  version[8] = 9;
  cases.push_back({"future version", version, "version"});
  for (const auto& c : cases) {
    const std::string path = tempPath(c.name);
    writeAll(path, c.data);
    try {
      target.load(path);
      ADD_FAILURE() << c.name << " was accepted";
    } catch (const MapIoError& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << c.name << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << "names the file";
    }
    expectSameMap(target, copy);
    std::remove(path.c_str());
  }
  EXPECT_THROW(target.load(tempPath("does_not_exist")), MapIoError);

  MapParams other = params();
  other.grid.resolution = 0.05;
  WaveletMap fine(other);
  try {
    fine.load(good);
    ADD_FAILURE() << "resolution mismatch accepted";
  } catch (const MapIoError& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
  std::remove(good.c_str());
}

// Files in the directory of `path` whose name starts with its file name followed by ".tmp".
std::vector<std::string> temporariesOf(const std::string& path) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  const std::string prefix = fs::path(path).filename().string() + ".tmp";
  for (const auto& e : fs::directory_iterator(fs::path(path).parent_path())) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) out.push_back(e.path().string());
  }
  return out;
}

TEST(MapIo, SaveLeavesNoTemporaryAndFailsClearly) {
  WaveletMap map(params());
  fill(&map, 8);
  const std::string path = tempPath("atomic.wavog");
  map.save(path);
  EXPECT_TRUE(temporariesOf(path).empty());
  map.save(path);  // over an existing map
  EXPECT_TRUE(temporariesOf(path).empty());
  try {
    map.save("/nonexistent_dir_wavog/x.wavog");
    ADD_FAILURE() << "save into a missing directory succeeded";
  } catch (const MapIoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent_dir_wavog/x.wavog"), std::string::npos)
        << e.what();
  }
  std::remove(path.c_str());
}

// The temporary used to be the predictable `<path>.tmp`, opened with truncation: a symlink
// planted there made save() overwrite the file it pointed to.
TEST(MapIo, SaveDoesNotFollowASymlinkAtTheOldTemporaryName) {
  WaveletMap map(params());
  fill(&map, 9);
  const std::string path = tempPath("planted.wavog");
  const std::string victim = tempPath("victim.txt");
  const std::vector<char> precious = {'k', 'e', 'e', 'p', '\n'};
  writeAll(victim, precious);
  std::remove((path + ".tmp").c_str());
  ASSERT_EQ(::symlink(victim.c_str(), (path + ".tmp").c_str()), 0) << std::strerror(errno);

  map.save(path);
  EXPECT_EQ(readAll(victim), precious) << "the symlink's target was written";
  WaveletMap loaded(params());
  loaded.load(path);
  expectSameMap(map, loaded);
  char target[512] = {};
  ASSERT_GT(::readlink((path + ".tmp").c_str(), target, sizeof(target) - 1), 0);
  EXPECT_EQ(std::string(target), victim) << "the planted link itself is left alone";
  EXPECT_EQ(temporariesOf(path).size(), 1u) << "only the planted link remains";

  // A symlink at the target itself is replaced by the map, never written through.
  const std::string linked = tempPath("linked.wavog");
  std::remove(linked.c_str());
  ASSERT_EQ(::symlink(victim.c_str(), linked.c_str()), 0);
  map.save(linked);
  EXPECT_EQ(readAll(victim), precious);
  struct stat st {};
  ASSERT_EQ(::lstat(linked.c_str(), &st), 0);
  EXPECT_TRUE(S_ISREG(st.st_mode));
  for (const auto& f : {path, path + ".tmp", victim, linked}) std::remove(f.c_str());
}

// Loads a path expected to be refused at once; returns the message.
std::string refusal(WaveletMap* map, const std::string& path) {
  try {
    map->load(path);
  } catch (const MapIoError& e) {
    return e.what();
  }
  ADD_FAILURE() << path << " was accepted";
  return "";
}

TEST(MapIo, LoadRefusesWhatIsNotARegularFile) {
  WaveletMap map(params());
  fill(&map, 10);
  WaveletMap copy(params());
  fill(&copy, 10);

  // A directory.
  const std::string dir = tempPath("a_directory");
  std::filesystem::create_directories(dir);
  std::string why = refusal(&map, dir);
  EXPECT_NE(why.find("a directory"), std::string::npos) << why;
  EXPECT_NE(why.find(dir), std::string::npos) << why;

  // /dev/zero: endless bytes (it used to be read until memory ran out).
  why = refusal(&map, "/dev/zero");
  EXPECT_NE(why.find("character device"), std::string::npos) << why;

  // A FIFO without a writer: opening it for reading used to block for ever. The load runs on
  // another thread; if it blocks, a writer is opened after a generous wait to release it, and the
  // test fails.
  const std::string fifo = tempPath("a_fifo");
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  auto pending = std::async(std::launch::async, [&] { return refusal(&map, fifo); });
  if (pending.wait_for(std::chrono::seconds(20)) != std::future_status::ready) {
    ADD_FAILURE() << "load() blocked on a FIFO";
    const int w = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (w >= 0) ::close(w);
  }
  why = pending.get();
  EXPECT_NE(why.find("FIFO"), std::string::npos) << why;
  EXPECT_NE(why.find(fifo), std::string::npos) << why;

  expectSameMap(map, copy);
  std::remove(fifo.c_str());
  std::filesystem::remove(dir);
}

// The header's block count bounds the file size both ways; a file outside the bounds is refused
// before its content is parsed (a larger one before it is read).
TEST(MapIo, FileSizeIsBoundByTheHeadersBlockCount) {
  WaveletMap source(params());
  fill(&source, 11);
  const std::string path = tempPath("bounded.wavog");
  source.save(path);
  const auto bytes = readAll(path);
  constexpr std::size_t kCountAt = 8 + 4 + 8 + 4 + 8 + 8;  // u64 block count in the header

  const auto withCount = [&](std::uint64_t count, std::size_t extra) {
    std::vector<char> out(bytes.begin(), bytes.end() - 4);
    std::memcpy(out.data() + kCountAt, &count, sizeof(count));
    out.resize(out.size() + extra, '\0');
    appendCrc(&out);
    return out;
  };
  WaveletMap target(params());
  // No block, a megabyte of content.
  writeAll(path, withCount(0, 1 << 20));
  std::string why = refusal(&target, path);
  EXPECT_NE(why.find("more than its 0 blocks can fill"), std::string::npos) << why;
  // More blocks than the bytes can hold.
  writeAll(path, withCount(std::uint64_t{1} << 60, 0));
  why = refusal(&target, path);
  EXPECT_NE(why.find("blocks cannot fit"), std::string::npos) << why;
  // The recomputed checksum alone does not make the original count wrong: it still loads.
  std::uint64_t count;
  std::memcpy(&count, bytes.data() + kCountAt, sizeof(count));
  writeAll(path, withCount(count, 0));
  target.load(path);
  expectSameMap(source, target);
  std::remove(path.c_str());
}

// Issue 28, item 3: a file that passed the CRC and load() with a block average of -1e57 turned
// non-finite after one ordinary scan (its float details overflowed) and could no longer be saved.
// The loader refuses log-odds beyond wavog::kMaxStoredLogOdds; at the bound the update stays
// finite.
TEST(MapIo, LogOddsTheUpdateCannotCarryAreRefused) {
  WaveletMap source(params());
  fill(&source, 12);
  const std::string path = tempPath("huge_logodds.wavog");
  source.save(path);
  const auto bytes = readAll(path);
  constexpr std::size_t kAverageAt = 8 + 4 + 8 + 4 + 8 + 8 + 8 + 4 + 4;  // block 0's f64 average
  constexpr std::size_t kFlagsAt = kAverageAt + 8, kDetailAt = kFlagsAt + 1;
  ASSERT_TRUE(bytes[kFlagsAt] & 4) << "block 0 has no root node";
  const auto patched = [&](std::size_t at, const void* value, std::size_t size) {
    std::vector<char> out(bytes.begin(), bytes.end() - 4);
    std::memcpy(out.data() + at, value, size);
    appendCrc(&out);
    return out;
  };
  RandomScans scans(12, 12.0);
  const auto s = scans.next();
  const auto everyValueFinite = [](const WaveletMap& map) {
    wavog::CellBox box;
    EXPECT_TRUE(map.bounds(0, &box));
    const auto r = map.exportScale(0, box, wavog::Aggregation::kMean);
    std::size_t bad = 0;
    for (float v : r.log_odds) bad += std::isfinite(v) ? 0 : 1;
    return bad;
  };
  for (double average : {-1e57, 1e57, -1.01e30}) {
    SCOPED_TRACE(average);
    writeAll(path, patched(kAverageAt, &average, sizeof(average)));
    WaveletMap target(params());
    const std::string why = refusal(&target, path);
    EXPECT_NE(why.find("beyond"), std::string::npos) << why;
    if (why.empty()) {  // before the fix: loaded, then NaN after one scan
      target.integrate(s.pose, s.view());
      EXPECT_EQ(everyValueFinite(target), 0u);
    }
  }
  const double detail = 1.01e30;  // finite, beyond the bound
  writeAll(path, patched(kDetailAt, &detail, sizeof(detail)));
  WaveletMap target(params());
  EXPECT_NE(refusal(&target, path).find("beyond"), std::string::npos);
  // At the bound: loads, and scans keep every value finite (and the map saves and loads again).
  for (double average : {-wavog::kMaxStoredLogOdds, wavog::kMaxStoredLogOdds}) {
    writeAll(path, patched(kAverageAt, &average, sizeof(average)));
    WaveletMap at_bound(params());
    ASSERT_NO_THROW(at_bound.load(path));
    for (int i = 0; i < 5; ++i) {
      const auto t = scans.next();
      at_bound.integrate(t.pose, t.view());
    }
    EXPECT_EQ(everyValueFinite(at_bound), 0u);
    at_bound.save(path);
    WaveletMap again(params());
    EXPECT_NO_THROW(again.load(path));
  }
  std::remove(path.c_str());
}

// Issue 42, item 3: a file whose block averages and details all sit at the bound loads, and holds
// cells far beyond it (an average plus up to three details per level). The details an update
// derived from such cells went beyond the bound (-1.1e30 after one scan), so the map saved a file
// it would not load, under 5 of the 6 policies. Every update keeps its coefficients within the
// bound now: whatever the map saves loads, and every value stays finite.
TEST(MapIo, AMapLoadedAtTheBoundSavesFilesThatLoad) {
  const double bound = wavog::kMaxStoredLogOdds;
  const std::string at_bound = tempPath("at_bound.wavog"), saved = tempPath("saved_again.wavog");
  std::size_t coefficients = 0;
  {
    WaveletMap source(params());
    fill(&source, 42);
    auto& im = wavog::MapAccess::impl(source);
    // Signs alternating by level and child: some cells add every detail on their path, and a
    // tile's cells (storage/tile.h) sit at the bound with alternating signs.
    std::function<void(wavog::detail::Node&, int)> set = [&](wavog::detail::Node& n, int l) {
      if (im.hasTile(n)) {
        im.withTile(n, [&](auto& t) {
          using T = std::remove_reference_t<decltype(t.v[0])>;
          const T at = wavog::detail::storedValue<T>(bound);  // a float rounds the bound up
          for (std::size_t i = 0; i < 64; ++i) t.v[i] = i % 3 == 0 ? at : -at;
          t.base = -bound;
        });
        coefficients += 65;
        return;
      }
      ++coefficients;
      const double sign = l % 2 == 0 ? 1.0 : -1.0;
      n.d[0] = sign * bound;
      n.d[1] = -sign * bound;
      n.d[2] = sign * bound;
      if (l <= 1) return;
      for (int q = 0; q < 4; ++q) {
        if (im.hasChild(n, q)) set(im.child(n, q), l - 1);
      }
    };
    std::size_t i = 0;
    for (auto& kv : im.blocks) {
      kv.second.s = (i++ % 2 == 0) ? bound : -bound;
      if (kv.second.has_root) set(kv.second.root, im.levels);
    }
    source.save(at_bound);
  }
  ASSERT_GT(coefficients, 1000u);
  for (const wavog::PolicyType type : everyPolicyType()) {
    SCOPED_TRACE(wavog::toString(type));
    MapParams p = MapParams::defaultsFor(type);
    p.grid.resolution = params().grid.resolution;
    p.grid.block_levels = params().grid.block_levels;
    WaveletMap map(p);
    ASSERT_NO_THROW(map.load(at_bound));
    wavog::CellBox box;
    ASSERT_TRUE(map.bounds(0, &box));
    const auto largest = [&box](const WaveletMap& m) {
      const auto r = m.exportScale(0, box, wavog::Aggregation::kMean);
      double most = 0.0;
      for (float v : r.log_odds) {
        EXPECT_TRUE(std::isfinite(v));
        most = std::max(most, std::fabs(static_cast<double>(v)));
      }
      return most;
    };
    EXPECT_GT(largest(map), 4.0 * bound);  // the file holds cells far beyond the bound
    RandomScans scans(7, 12.0);
    for (int k = 0; k < 3; ++k) {
      const auto s = scans.next();
      map.integrate(s.pose, s.view());
      map.save(saved);
      WaveletMap again(p);
      std::string why;
      try {
        again.load(saved);
      } catch (const MapIoError& e) {
        why = e.what();
      }
      EXPECT_EQ(why, "") << "after scan " << k;
      if (!why.empty()) break;
      EXPECT_LT(largest(again), 40.0 * bound);
    }
    // Clearing a box beside such cells writes details too.
    map.clearBox(-3.0, -3.0, 1.0, 1.0);
    map.save(saved);
    WaveletMap cleared(p);
    EXPECT_NO_THROW(cleared.load(saved));
  }
  std::remove(at_bound.c_str());
  std::remove(saved.c_str());
}

// Issue 28, item 5 (core side): a caller configured without reflection or NDT can tell that a
// file's payload would be dropped.
TEST(MapIo, InspectFileSaysWhichPayloadsAFileHolds) {
  const std::string path = tempPath("inspect.wavog");
  for (int mask = 0; mask < 4; ++mask) {
    MapParams p = params();
    p.reflection = (mask & 1) != 0;
    p.ndt = (mask & 2) != 0;
    WaveletMap map(p);
    fill(&map, 13);
    map.save(path);
    const wavog::MapFileContents c = WaveletMap::inspectFile(path);
    EXPECT_EQ(c.reflection, p.reflection) << mask;
    EXPECT_EQ(c.ndt, p.ndt) << mask;
    // A map without them drops them: its own save holds neither.
    WaveletMap plain(params());
    plain.load(path);
    plain.save(path);
    const wavog::MapFileContents dropped = WaveletMap::inspectFile(path);
    EXPECT_FALSE(dropped.reflection || dropped.ndt) << mask;
  }
  // Older versions: the version-2 fixture's reflection layers, the version-1 fixture's nothing.
  const std::string data = std::string(WAVOG_SOURCE_DIR) + "/test/core/data/";
  const wavog::MapFileContents v2 = WaveletMap::inspectFile(data + "reflection_v2.wavog");
  EXPECT_TRUE(v2.reflection);
  EXPECT_FALSE(v2.ndt);
  const wavog::MapFileContents v1 = WaveletMap::inspectFile(data + "forget_v1.wavog");
  EXPECT_FALSE(v1.reflection || v1.ndt);
  EXPECT_THROW(WaveletMap::inspectFile(tempPath("missing.wavog")), MapIoError);
  writeAll(path, std::vector<char>(100, 'x'));
  EXPECT_THROW(WaveletMap::inspectFile(path), MapIoError);
  std::remove(path.c_str());
}


// Hand-built files: the header and the payload sections of an empty map saved under `p`, with
// the blocks `blocks` (the version-6 encoding, block count `count`) in place of none.
std::vector<char> fileWithBlocks(const MapParams& p, std::uint64_t count,
                                 const std::vector<char>& blocks) {
  const std::string path = tempPath("empty.wavog");
  WaveletMap(p).save(path);
  const auto empty = readAll(path);
  std::remove(path.c_str());
  constexpr std::size_t kCountAt = 8 + 4 + 8 + 4 + 8 + 8;  // u64 block count in the header
  std::vector<char> out(empty.begin(), empty.begin() + kCountAt);
  const auto* c = reinterpret_cast<const char*>(&count);
  out.insert(out.end(), c, c + sizeof(count));
  out.insert(out.end(), blocks.begin(), blocks.end());
  out.insert(out.end(), empty.begin() + kCountAt + 8, empty.end() - 4);
  appendCrc(&out);
  return out;
}

struct BlockBytes {
  std::vector<char> bytes;
  template <typename T>
  BlockBytes& put(T v) {
    const auto* b = reinterpret_cast<const char*>(&v);
    bytes.insert(bytes.end(), b, b + sizeof(v));
    return *this;
  }
  // Block (bx, by), average s, flags (1 known_all, 2 known_any, 4 has_root).
  BlockBytes& block(std::int32_t bx, std::int32_t by, double s, std::uint8_t flags) {
    return put(bx).put(by).put(s).put(flags);
  }
  // A node: details (f64 since version 6), no pending count, child mask and knowledge bits.
  BlockBytes& node(double dx, double dy, double dxy, std::uint8_t mask, std::uint8_t all,
                   std::uint8_t any) {
    return put(dx).put(dy).put(dxy).put(std::uint16_t{0}).put(mask).put(all).put(any);
  }
};

// What a map can hold and a file must not claim otherwise (fuzz findings of issue 28): a slot
// without a node of its own (a finest cell, a uniform child, a block without a root) is observed
// entirely or not at all, and a node's knowledge is the one its parent (or block) records for its
// slot. A file breaking either loaded and read differently by each path: the max read-out found
// no observed cell under a slot marked observed (-inf at scale 1), and value() read the prior for
// a finest cell the read-out showed observed (-1.66). Such files are refused.
TEST(MapIo, KnowledgeTheMapCannotHoldIsRefused) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = 0.25;
  p.grid.block_levels = 2;
  const std::string path = tempPath("knowledge.wavog");
  const wavog::CellBox cells{0, 0, 4, 4};
  // value() / isObserved() of each finest cell, against the scale-0 read-out; every value of
  // the max read-out at every scale finite.
  const auto readsAgree = [&](const WaveletMap& map) {
    const wavog::Raster r = map.exportScale(0, cells, wavog::Aggregation::kMean);
    for (std::int64_t y = 0; y < 4; ++y) {
      for (std::int64_t x = 0; x < 4; ++x) {
        const auto i = static_cast<std::size_t>(y * 4 + x);
        if (map.isObserved({x, y}) != (r.known[i] != 0)) return false;
        if (r.known[i] && map.value({x, y}) != r.log_odds[i]) return false;
      }
    }
    for (int s = 0; s <= 2; ++s) {
      const wavog::CellBox box{0, 0, std::int64_t{4} >> s, std::int64_t{4} >> s};
      for (float v : map.exportScale(s, box, wavog::Aggregation::kMax).log_odds) {
        if (!std::isfinite(v)) return false;
      }
    }
    return true;
  };
  // A file consistent in every bit loads, and each path reads it alike: cell 0 observed.
  BlockBytes good;
  good.block(0, 0, -0.1, 6).node(0.2f, -0.2f, 0.4f, 1, 0, 1).node(0.4f, 0.4f, -0.8f, 0, 1, 1);
  writeAll(path, fileWithBlocks(p, 1, good.bytes));
  {
    WaveletMap map(p);
    ASSERT_NO_THROW(map.load(path));
    EXPECT_TRUE(map.isObserved({0, 0}));
    EXPECT_FALSE(map.isObserved({1, 0}));
    EXPECT_TRUE(readsAgree(map));
  }
  struct Case {
    const char* what;
    BlockBytes file;
    const char* reason;
  };
  std::vector<Case> cases;
  // The finding fuzz_map_load_scale1_minus_inf: the root marks child 0 observed, the child holds
  // no observed cell (the max read-out at scale 1 read -inf).
  cases.push_back({"child unobserved under an observed slot", {}, "disagrees"});
  cases.back().file.block(0, 0, -0.1, 6).node(0.2f, -0.2f, 0.4f, 1, 0, 1).node(0.4f, 0.4f, -0.8f,
                                                                                0, 0, 0);
  // The child holds an observed cell, the root marks its slot unobserved.
  cases.push_back({"child observed under an unobserved slot", {}, "disagrees"});
  cases.back().file.block(0, 0, -0.1, 6).node(0.2f, -0.2f, 0.4f, 1, 2, 2).node(0.4f, 0.4f, -0.8f,
                                                                                0, 1, 1);
  // The block records no knowledge, its root a fully observed subtree.
  cases.push_back({"root observed in an unobserved block", {}, "disagrees"});
  cases.back().file.block(0, 0, -0.1, 4).node(0.2f, -0.2f, 0.4f, 0, 0xF, 0xF);
  // The finding fuzz_map_load_value_vs_readout: a finest cell marked partly observed (known_any
  // without known_all; value() read the prior, the read-out -1.66).
  cases.push_back({"finest cell partly observed", {}, "partly observed"});
  cases.back().file.block(0, 0, -0.1, 6).node(0.2f, -0.2f, 0.4f, 1, 0, 1).node(0.4f, 0.4f, -0.8f,
                                                                                0, 0, 1);
  // A uniform 2 x 2 child partly observed, and a block without a root partly observed.
  cases.push_back({"uniform child partly observed", {}, "partly observed"});
  cases.back().file.block(0, 0, -0.1, 6).node(0.2f, -0.2f, 0.4f, 0, 0, 1);
  cases.push_back({"uniform block partly observed", {}, "partly observed"});
  cases.back().file.block(0, 0, -1.5, 2);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    writeAll(path, fileWithBlocks(p, 1, c.file.bytes));
    WaveletMap map(p);
    const std::string why = refusal(&map, path);
    EXPECT_NE(why.find(c.reason), std::string::npos) << why;
    EXPECT_EQ(map.stats().blocks, 0u);
    if (why.empty()) {  // before the fix: loaded, and read differently by each path
      EXPECT_TRUE(readsAgree(map));
    }
  }
  std::remove(path.c_str());
}

// Fuzz finding of issue 28 (fuzz_map_load): a clamp map with a reflection map (hit cells keep
// pairs of counts) loaded from a file whose log-odds are huge (a detail of 5.44e15, within
// kMaxStoredLogOdds): reflection(cell) read 1 and exportReflection(0, ...) 0.5 for the same cell.
// A paired cell's misses were read as l / odd_emp plus the pair's difference to it: the terms
// cancel in the point query's double log-odds, not with the read-out's float ones. Both now read a
// paired cell's misses from its pair alone.
TEST(MapIo, ReflectionPointQueryAgreesWithReadOutAtLargeLogOdds) {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = 0.1;
  p.grid.block_levels = 5;
  p.reflection = true;
  WaveletMap source(p);
  fill(&source, 14);
  const std::string path = tempPath("reflection_large.wavog");
  source.save(path);
  auto bytes = readAll(path);
  constexpr std::size_t kFlagsAt = 8 + 4 + 8 + 4 + 8 + 8 + 8 + 4 + 4 + 8;  // block 0's flags
  ASSERT_TRUE(bytes[kFlagsAt] & 4) << "block 0 has no root node";
  const double detail = 5.44e15;  // block 0's root dy (f64 since version 6)
  std::memcpy(bytes.data() + kFlagsAt + 1 + 8, &detail, sizeof(detail));
  bytes.resize(bytes.size() - 4);
  appendCrc(&bytes);
  writeAll(path, bytes);
  WaveletMap map(p);
  ASSERT_NO_THROW(map.load(path));
  wavog::CellBox box;
  ASSERT_TRUE(map.bounds(0, &box));
  const wavog::ReflectionRaster r = map.exportReflection(0, box);
  std::size_t compared = 0, differ = 0;
  for (std::int64_t y = box.min_y, i = 0; y < box.max_y; ++y) {
    for (std::int64_t x = box.min_x; x < box.max_x; ++x, ++i) {
      const float a = map.reflection({x, y}), b = r.p[static_cast<std::size_t>(i)];
      if (std::isnan(a) && std::isnan(b)) continue;
      ++compared;
      if (!(std::fabs(a - b) <= 1e-5f)) ++differ;
    }
  }
  EXPECT_GT(compared, 0u);
  EXPECT_EQ(differ, 0u) << "of " << compared << " observed cells";
  std::remove(path.c_str());
}

// Fuzz finding of issue 28 (fuzz_map_load_pairs_round_trip): a clamp map with a reflection map
// loaded from a file whose details (-6.0e7, -4.3e8, within kMaxStoredLogOdds) put hit cells far
// from their bounds (a hit cell at 7.7e7), then saved and loaded again, read other reflection
// values. A pair keeps its cell's log-odds as a float: the loader sets it from the cell's double
// log-odds, and each read took the difference, the float's round-off (up to 4 at 7.7e7), for up to
// round(4 / 0.4) = 10 misses since; a save wrote them into the pair and the next load added them
// again. Round-off of that size is no miss (pairNow, kUnmovedRelative): the read-out survives
// round trips. Under each clamp policy: "clamp_lower" (no upper bound) and "clamp_upper" (no
// lower one) reach such log-odds by updates too, on their unbounded side, so that a loader bound
// would not do for them.
TEST(MapIo, ReflectionPairsSurviveARoundTripAtLargeLogOdds) {
  const std::string path = tempPath("reflection_pairs.wavog");
  for (auto policy : {wavog::PolicyType::kClamp, wavog::PolicyType::kClampLower,
                      wavog::PolicyType::kClampUpper}) {
    // Block 0's cells at ~ +-7.7e7 (a float's spacing there: 8) and at eight offsets, so that
    // some hit cells' log-odds round to a float above them, some below.
    for (int k = -8; k < 8; ++k) {
      const double average = k < 0 ? -7.7e7 + k : 7.7e7 + k;
      SCOPED_TRACE(std::to_string(static_cast<int>(policy)) + " " + std::to_string(average));
      MapParams p = MapParams::defaultsFor(policy);
      p.grid.resolution = 0.1;
      p.grid.block_levels = 5;
      p.reflection = true;
      WaveletMap source(p);
      fill(&source, 14);
      source.save(path);
      auto bytes = readAll(path);
      constexpr std::size_t kAverageAt = 8 + 4 + 8 + 4 + 8 + 8 + 8 + 4 + 4;  // block 0's average
      std::memcpy(bytes.data() + kAverageAt, &average, sizeof(average));
      bytes.resize(bytes.size() - 4);
      appendCrc(&bytes);
      writeAll(path, bytes);
      WaveletMap map(p);
      ASSERT_NO_THROW(map.load(path));
      wavog::CellBox box;
      ASSERT_TRUE(map.bounds(0, &box));
      const wavog::ReflectionRaster first = map.exportReflection(0, box);
      for (int trip = 1; trip <= 2; ++trip) {
        map.save(path);
        WaveletMap again(p);
        ASSERT_NO_THROW(again.load(path));
        const wavog::ReflectionRaster r = again.exportReflection(0, box);
        ASSERT_EQ(r.p.size(), first.p.size());
        std::size_t compared = 0, differ = 0;
        for (std::size_t i = 0; i < r.p.size(); ++i) {
          if (std::isnan(first.p[i]) && std::isnan(r.p[i])) continue;
          ++compared;
          if (std::memcmp(&first.p[i], &r.p[i], sizeof(float)) != 0) ++differ;
        }
        EXPECT_GT(compared, 0u);
        EXPECT_EQ(differ, 0u) << "of " << compared << " observed cells, round trip " << trip;
        map.load(path);
      }
    }
  }
  std::remove(path.c_str());
}


// Fuzz finding of issue 28 (fuzz_map_load): the seed finding_i28_pairs_round_trip with its
// reflection mode byte 1 (derived) turned to 2 ("prior", h + m = 1 from the occupancy alone, which
// only "forget" with the empty_bound prior keeps) loaded into a clamp map, and reflection(-6, -5)
// read 0.667 (the cell's pair) where the read-out read 1 (the occupancy). Such a file is refused;
// "prior" under "forget" still loads.
TEST(MapIo, ReflectionModeThePolicyNeverKeepsIsRefused) {
  const auto seed = readAll(std::string(WAVOG_SOURCE_DIR) +
                            "/test/fuzz/corpus/fuzz_map_load/finding_i28_pairs_round_trip");
  ASSERT_GT(seed.size(), 1968u);
  // fuzz_map_load's framing (mode byte 0x81: framed version 5, clamp, reflection).
  const auto frame = [](std::vector<char> body) {
    std::vector<char> out = {'W', 'A', 'V', 'O', 'G', 'M', 'A', 'P'};
    const std::uint32_t version = 5;
    const auto* v = reinterpret_cast<const char*>(&version);
    out.insert(out.end(), v, v + sizeof(version));
    out.insert(out.end(), body.begin() + 1, body.end());
    appendCrc(&out);
    return out;
  };
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = 0.2;
  p.grid.block_levels = 4;
  p.reflection = true;
  const std::string path = tempPath("reflection_mode.wavog");
  constexpr std::size_t kModeAt = 1967;  // the reflection mode byte in the seed (1: derived)
  ASSERT_EQ(seed[kModeAt], 1);
  writeAll(path, frame(seed));
  {
    WaveletMap map(p);
    ASSERT_NO_THROW(map.load(path));
  }
  auto prior = seed;
  prior[kModeAt] = 2;
  writeAll(path, frame(prior));
  WaveletMap map(p);
  const std::string why = refusal(&map, path);
  EXPECT_NE(why.find("only forget keeps it"), std::string::npos) << why;
  EXPECT_EQ(map.stats().blocks, 0u);
  if (why.empty()) {  // before the fix: loaded, and the point query and read-out disagreed
    const wavog::CellBox box{-6, -5, -5, -4};
    EXPECT_NEAR(map.reflection({-6, -5}), map.exportReflection(0, box).p[0], 1e-5f);
  }
  // "prior" under "forget" (an empty map of that mode) loads.
  MapParams f = MapParams::defaultsFor(wavog::PolicyType::kForget);
  f.policy.init = wavog::InitValue::kEmptyBound;
  f.reflection = true;
  WaveletMap forget(f);
  forget.save(path);
  WaveletMap back(f);
  EXPECT_NO_THROW(back.load(path));
  std::remove(path.c_str());
}

}  // namespace
}  // namespace wavog_test
