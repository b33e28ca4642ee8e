// Helpers shared by the tests that run the tools as programs (test_log2bag, test_offline): a
// scratch directory per test process, a program run with its stderr captured, whole-file reads and
// the shared data directory.
#ifndef WAVOG_MAPPING_TEST_TOOLS_PROGRAM_RUNNER_H_
#define WAVOG_MAPPING_TEST_TOOLS_PROGRAM_RUNNER_H_

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "wavog_mapping/io/carmen_reader.h"

namespace wavog_tool_test {

/// Exit status of a program run (-1 if it did not exit normally) and what it wrote to stderr.
struct RunResult {
  int status = -1;
  std::string err;
};

/// Removes a scratch directory once every test of the program has run:
/// `::testing::AddGlobalTestEnvironment(new RemoveAtEnd(workDir()))`.
class RemoveAtEnd : public ::testing::Environment {
 public:
  explicit RemoveAtEnd(std::filesystem::path dir) : dir_(std::move(dir)) {}
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

 private:
  std::filesystem::path dir_;
};

/// A new, empty directory <tmp>/<name>_<pid> (emptied if it exists).
inline std::filesystem::path freshDir(const std::string& name) {
  const std::filesystem::path d =
      std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// The whole content of a file ("" if it cannot be read).
inline std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Runs `program args` through the shell, its stderr captured in `dir`/stderr.txt.
inline RunResult runProgram(const std::string& program, const std::string& args,
                            const std::filesystem::path& dir) {
  const std::filesystem::path err = dir / "stderr.txt";
  const std::string cmd = program + " " + args + " 2> " + err.string();
  RunResult r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.err = readText(err);
  return r;
}

/// Path of a file of the shared data directory (../shared/data or WAVOG_DATA_DIR); "" when there
/// is no data directory.
inline std::string dataFile(const std::string& name) {
  const std::string dir = wavog::findDataDir(WAVOG_SOURCE_DIR);
  return dir.empty() ? "" : (std::filesystem::path(dir) / name).string();
}

}  // namespace wavog_tool_test

#endif  // WAVOG_MAPPING_TEST_TOOLS_PROGRAM_RUNNER_H_
