// Save / load: exact round trip; truncated, corrupted, foreign and mismatched files rejected with
// the map left unchanged.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::MapIoError;
using wavog::MapParams;
using wavog::WaveletMap;

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "wavog_io_" + name;
}

std::vector<char> readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
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

TEST(MapIo, SaveLeavesNoTemporaryAndFailsClearly) {
  WaveletMap map(params());
  fill(&map, 8);
  const std::string path = tempPath("atomic.wavog");
  map.save(path);
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());
  EXPECT_THROW(map.save("/nonexistent_dir_wavog/x.wavog"), MapIoError);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace wavog_test
