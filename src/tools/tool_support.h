// Shared pieces of the command-line tools (wavog_log2bag, wavog_offline, wavog_simulate,
// wavog_evaluate, wavog_compare): the plan of a CARMEN log (lasers, their frames and topics,
// duplicates), time stamp repair, planar pose algebra, a terminal progress bar, the command line
// (CLI11: strict numbers, one main()), JSON files (nlohmann-json) and small text helpers. No ROS.
// Not thread-safe.
#ifndef WAVOG_MAPPING_TOOLS_TOOL_SUPPORT_H_
#define WAVOG_MAPPING_TOOLS_TOOL_SUPPORT_H_

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "wavog_mapping/core/types.h"

namespace wavog_tools {

// Planar pose algebra: the core's (wavog_mapping/core/types.h).
using wavog::compose;
using wavog::inverse;
using wavog::wrapAngle;

/// One laser of a CARMEN log and how it appears in ROS.
struct CarmenLaser {
  std::string type;       ///< "FLASER", "RLASER" or "ROBOTLASER1"
  std::string frame;      ///< frame id, e.g. "front_laser" (no leading slash)
  std::string topic;      ///< topic, e.g. "/front_laser/scan"
  std::size_t scans = 0;  ///< scans of this type in the log
  bool used = true;       ///< false: ROBOTLASER1 repeating the FLASER laser (skipped)
  /// Laser pose in base_link: robot_pose^-1 * laser_pose of its first scan (identity when the
  /// log's robot pose is not in the laser pose's frame: offset > kMaxMountOffset).
  wavog::Pose2 mount;
  bool mount_from_log = false;  ///< true if `mount` came from the log, false: identity fallback
};

/// What a first pass over a CARMEN log found.
struct CarmenLogPlan {
  std::vector<CarmenLaser> lasers;     ///< in order of first appearance
  std::size_t scans_used = 0;          ///< scans of the used lasers (all of the log)
  std::size_t skipped_duplicates = 0;  ///< ROBOTLASER1 scans skipped because FLASER is present
  std::string read_error;  ///< a truncated / corrupted stream met by the first pass (else empty)
  /// The laser of a scan type, or nullptr if that type is not used.
  const CarmenLaser* laserFor(const std::string& type) const;
};

/// Largest plausible laser mount offset (m) from base_link.
constexpr double kMaxMountOffset = 2.0;

/// Reads the whole log once (malformed lines skipped silently) and plans the conversion: FLASER
/// and ROBOTLASER1 are the front laser ("front_laser"), RLASER the rear ("rear_laser"); when a
/// log has both FLASER and ROBOTLASER1 lines they repeat the same laser and ROBOTLASER1 is
/// skipped. Throws std::runtime_error if the file cannot be opened.
CarmenLogPlan planCarmenLog(const std::string& path);

/// Makes scan time stamps strictly increasing and absolute. Relative stamps (the first valid one
/// below kRelativeLimit) are shifted by `epoch`; missing ones (<= 0 or not finite) are set to the
/// previous stamp plus 1 / rate; a stamp not after the previous one becomes previous + kMinStep.
/// Stamps are rounded to whole microseconds (CARMEN's precision); see toSecNsec().
class StampRepair {
 public:
  static constexpr double kRelativeLimit = 1e8;  ///< s; 1973, earlier than any real log
  static constexpr double kMinStep = 1e-6;       ///< s

  StampRepair(double rate_hz, double epoch) : period_(1.0 / rate_hz), epoch_(epoch) {}
  /// The repaired stamp (s) for the next raw stamp (s).
  double repair(double raw);

  std::size_t shifted() const { return shifted_; }
  std::size_t clamped() const { return clamped_; }
  std::size_t synthesised() const { return synthesised_; }
  double offset() const { return offset_; }
  double largestBackwardStep() const { return largest_back_; }
  /// One line per repair kind that happened, for the end-of-run report.
  std::vector<std::string> report() const;

 private:
  double period_;
  double epoch_;
  double offset_ = 0.0;
  bool offset_known_ = false;
  bool have_last_ = false;
  double last_ = 0.0;
  double largest_back_ = 0.0;
  std::size_t shifted_ = 0;
  std::size_t clamped_ = 0;
  std::size_t synthesised_ = 0;
};

/// Splits a stamp (s) into whole seconds and nanoseconds rounded to whole microseconds, so that
/// a logged "1134864642.914187" becomes exactly 1134864642 s + 914187000 ns.
void toSecNsec(double stamp, std::uint32_t* sec, std::uint32_t* nsec);

/// Progress on stderr: on a terminal a bar redrawn in place (done / total, scans/s, ETA), at most
/// 10 times a second; otherwise a plain line every 10 % of the total.
class ProgressBar {
 public:
  ProgressBar(std::size_t total, bool enabled);
  void update(std::size_t done);
  /// Final line (always printed when enabled).
  void finish(std::size_t done);

 private:
  void draw(std::size_t done, bool final_line);

  std::size_t total_;
  bool enabled_;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::size_t next_decile_ = 1;
};

/// Writes `json` to `path`, indented by two, with a final newline; throws std::runtime_error naming
/// the file when it cannot be written.
void writeJson(const std::string& path, const nlohmann::ordered_json& json);
/// "a,b,c" -> {"a", "b", "c"} (empty fields dropped).
std::vector<std::string> splitList(const std::string& text);
/// Strips one leading '/' (tf2 rejects frame ids that start with one).
std::string stripSlash(const std::string& frame);

/// A command-line number: the whole of `text` must be a finite number, else
/// std::invalid_argument("<flag>: not a number: '<text>'").
double parseNumber(const std::string& flag, const char* text);
/// A command-line whole number >= min_value: std::invalid_argument("<flag>: not a whole number
/// >= <min>: '<text>'") otherwise (trailing characters, fractions and overflow included).
long parseInteger(const std::string& flag, const char* text, long min_value);

/// The long name of a CLI11 option list: "-o,--out" -> "--out".
std::string longName(const std::string& names);

/// An option whose value is read whole by parseNumber (`--rate 0.05x` is an error naming the
/// option, exit status 1); its current value is the default shown by --help.
CLI::Option* addNumber(CLI::App* app, const std::string& names, double* value,
                       const std::string& help);

/// An option whose value is read whole by parseInteger(min_value); the default as addNumber.
template <typename T>
CLI::Option* addInteger(CLI::App* app, const std::string& names, T* value, long min_value,
                        const std::string& help) {
  const std::string flag = longName(names);
  return app
      ->add_option_function<std::string>(
          names,
          [flag, value, min_value](const std::string& text) {
            *value = static_cast<T>(parseInteger(flag, text.c_str(), min_value));
          },
          help)
      ->type_name("INT")
      ->default_str(std::to_string(*value));
}

/// Width of the tools' --help descriptions.
constexpr std::size_t kHelpWidth = 96;

/// The main() of every tool: parses the command line with `app` (--help: the generated help on
/// stdout, status 0; a usage error: "<name>: error: <what>" and the help on stderr, status 2),
/// then returns `run`'s status; any exception (a bad number included) prints
/// "<name>: error: <what>" and gives status 1.
int runTool(CLI::App* app, int argc, char** argv, const std::function<int()>& run);

/// `text` broken at spaces into lines of at most `width` characters (longer words stay whole).
std::string wrapText(const std::string& text, std::size_t width);

/// A whole main(): `add_options` declares the options of a default `Options` on an app called
/// `name` (its --help shows `description`), then runTool with `run`.
template <typename Options>
int toolMain(int argc, char** argv, const char* name, const char* description,
             void (*add_options)(CLI::App*, Options*), int (*run)(const Options&)) {
  Options options;
  CLI::App app{wrapText(description, kHelpWidth), name};
  add_options(&app, &options);
  return runTool(&app, argc, argv, [&] { return run(options); });
}

}  // namespace wavog_tools

#endif  // WAVOG_MAPPING_TOOLS_TOOL_SUPPORT_H_
