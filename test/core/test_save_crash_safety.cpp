// Crash safety of WaveletMap::save(): a child process saving in a loop is killed with SIGKILL at
// random moments, many times; the file on disk must always be one of the two complete maps the
// child writes, and load.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <thread>

#include "test_support.h"

namespace wavog_test {
namespace {

using wavog::MapParams;
using wavog::WaveletMap;

constexpr int kKills = 200;

MapParams params() {
  MapParams p = MapParams::defaultsFor(wavog::PolicyType::kClamp);
  p.grid.resolution = 0.05;
  p.grid.block_levels = 6;
  return p;
}

std::vector<char> readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void fill(WaveletMap* map, std::uint32_t seed, int scans, double half_extent) {
  RandomScans random(seed, half_extent);
  for (int i = 0; i < scans; ++i) {
    const auto s = random.next();
    map->integrate(s.pose, s.view());
  }
}

// Removes the temporaries a killed save left beside `path`; returns how many there were.
int removeTemporaries(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string prefix = fs::path(path).filename().string() + ".tmp";
  std::vector<fs::path> found;
  for (const auto& e : fs::directory_iterator(fs::path(path).parent_path())) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) found.push_back(e.path());
  }
  for (const auto& f : found) fs::remove(f);
  return static_cast<int>(found.size());
}

TEST(SaveCrashSafety, KillNineDuringSaveLeavesTheOldOrTheNewMap) {
  const std::string dir = ::testing::TempDir() + "wavog_crash_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/map.wavog";

  // Two different maps; B is the larger, so a save of it takes a while.
  WaveletMap a(params()), b(params());
  fill(&a, 21, 20, 8.0);
  fill(&b, 22, 200, 30.0);
  a.save(dir + "/a.wavog");
  const auto t0 = std::chrono::steady_clock::now();
  b.save(dir + "/b.wavog");
  const double save_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  const auto bytes_a = readAll(dir + "/a.wavog");
  const auto bytes_b = readAll(dir + "/b.wavog");
  ASSERT_NE(bytes_a, bytes_b);
  a.save(path);

  std::mt19937 rng(1234);
  // Kill moments spread over about three saves of B (and one of A) after the fork.
  std::uniform_real_distribution<double> delay_us(0.0, 3.0 * save_us);
  int saw_a = 0, saw_b = 0, left_temporaries = 0;
  for (int i = 0; i < kKills; ++i) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      // The child only saves, for ever, alternating the maps; it never returns into gtest.
      try {
        for (;;) {
          b.save(path);
          a.save(path);
        }
      } catch (...) {
        ::_exit(2);
      }
    }
    std::this_thread::sleep_for(std::chrono::duration<double, std::micro>(delay_us(rng)));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status))
        << "the child stopped by itself (a save threw), status " << status;

    const auto now = readAll(path);
    if (now == bytes_a) {
      ++saw_a;
    } else if (now == bytes_b) {
      ++saw_b;
    } else {
      FAIL() << "kill " << i << ": the file is neither map (" << now.size() << " bytes)";
    }
    WaveletMap loaded(params());
    ASSERT_NO_THROW(loaded.load(path)) << "kill " << i;
    left_temporaries += removeTemporaries(path);
  }
  std::printf("%d kills (save of B: %.0f us): old/new map A %d, B %d; %d killed mid-write\n",
              kKills, save_us, saw_a, saw_b, left_temporaries);
  // The kills did land both between and inside saves; otherwise the test proved nothing.
  EXPECT_GT(saw_b, 0);
  EXPECT_GT(left_temporaries, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace wavog_test
