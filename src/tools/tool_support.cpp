#include "tool_support.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "wavog_mapping/io/carmen_reader.h"

namespace wavog_tools {
namespace {

constexpr double kRedrawSeconds = 0.1;
constexpr int kBarWidth = 30;

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const long s = std::lround(seconds);
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%02ld:%02ld", s / 60, s % 60);
  return buf;
}

}  // namespace

const CarmenLaser* CarmenLogPlan::laserFor(const std::string& type) const {
  for (const auto& laser : lasers) {
    if (laser.type == type) return laser.used ? &laser : nullptr;
  }
  return nullptr;
}

CarmenLogPlan planCarmenLog(const std::string& path) {
  CarmenLogPlan plan;
  wavog::CarmenReader reader(path, false);
  wavog::CarmenScan scan;
  try {
    while (reader.next(&scan)) {
      auto it = std::find_if(plan.lasers.begin(), plan.lasers.end(),
                             [&](const CarmenLaser& l) { return l.type == scan.type; });
      if (it == plan.lasers.end()) {
        CarmenLaser laser;
        laser.type = scan.type;
        laser.frame = scan.type == "RLASER" ? "rear_laser" : "front_laser";
        laser.topic = "/" + laser.frame + "/scan";
        const wavog::Pose2 mount = compose(inverse(scan.robot_pose), scan.laser_pose);
        if (std::hypot(mount.x, mount.y) <= kMaxMountOffset) {
          laser.mount = mount;
          laser.mount_from_log = true;
        }
        plan.lasers.push_back(laser);
        it = plan.lasers.end() - 1;
      }
      ++it->scans;
    }
  } catch (const std::runtime_error& e) {
    plan.read_error = e.what();  // met again, at its place, by the second pass
  }
  const bool has_flaser = plan.laserFor("FLASER") != nullptr;
  for (auto& laser : plan.lasers) {
    if (laser.type == "ROBOTLASER1" && has_flaser) {
      laser.used = false;
      plan.skipped_duplicates += laser.scans;
    }
    if (laser.used) plan.scans_used += laser.scans;
  }
  return plan;
}

double StampRepair::repair(double raw) {
  double t = 0.0;
  if (!std::isfinite(raw) || raw <= 0.0) {
    t = have_last_ ? last_ + period_ : epoch_;
    ++synthesised_;
  } else {
    if (!offset_known_) {
      offset_ = raw < kRelativeLimit ? epoch_ : 0.0;
      offset_known_ = true;
    }
    if (offset_ != 0.0) ++shifted_;
    t = raw + offset_;
  }
  // Logs print microseconds: keep exactly those (a double near 1e9 s resolves ~0.2 us).
  t = std::round(t * 1e6) / 1e6;
  if (have_last_ && !(t > last_)) {
    largest_back_ = std::max(largest_back_, last_ - t);
    t = last_ + kMinStep;
    ++clamped_;
  }
  last_ = t;
  have_last_ = true;
  return t;
}

std::vector<std::string> StampRepair::report() const {
  std::vector<std::string> lines;
  if (shifted_ > 0) {
    std::ostringstream s;
    s << shifted_ << " relative time stamps shifted by " << std::fixed << std::setprecision(0)
      << offset_ << " s (--epoch)";
    lines.push_back(s.str());
  }
  if (clamped_ > 0) {
    std::ostringstream s;
    s << clamped_ << " time stamps not after the previous one clamped to previous + 1 us "
      << "(largest backward step " << largest_back_ << " s)";
    lines.push_back(s.str());
  }
  if (synthesised_ > 0) {
    std::ostringstream s;
    s << synthesised_ << " missing (zero) time stamps synthesised at " << 1.0 / period_
      << " Hz (--rate)";
    lines.push_back(s.str());
  }
  return lines;
}

void toSecNsec(double stamp, std::uint32_t* sec, std::uint32_t* nsec) {
  double whole = std::floor(stamp);
  long long usec = std::llround((stamp - whole) * 1e6);
  if (usec >= 1000000) {
    whole += 1.0;
    usec -= 1000000;
  }
  *sec = static_cast<std::uint32_t>(whole);
  *nsec = static_cast<std::uint32_t>(usec * 1000);
}

ProgressBar::ProgressBar(std::size_t total, bool enabled)
    : total_(total),
      enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

void ProgressBar::update(std::size_t done) {
  if (!enabled_) return;
  if (tty_) {
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_draw_).count() < kRedrawSeconds) return;
    last_draw_ = now;
    draw(done, false);
  } else if (total_ > 0 && done * 10 >= next_decile_ * total_ && next_decile_ < 10) {
    while (next_decile_ < 10 && done * 10 >= next_decile_ * total_) ++next_decile_;
    draw(done, false);
  }
}

void ProgressBar::finish(std::size_t done) {
  if (enabled_) draw(done, true);
}

void ProgressBar::draw(std::size_t done, bool final_line) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
  const double eta = rate > 0 && total_ >= done ? static_cast<double>(total_ - done) / rate : -1;
  const double fraction =
      total_ > 0 ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total_)) : 1.0;
  std::ostringstream s;
  if (tty_) {
    const int filled = static_cast<int>(fraction * kBarWidth);
    s << "\r[" << std::string(static_cast<std::size_t>(filled), '#')
      << std::string(static_cast<std::size_t>(kBarWidth - filled), ' ') << "] ";
  }
  s << done << "/" << total_ << " scans " << std::fixed << std::setprecision(0) << rate
    << " scans/s ";
  if (final_line) {
    s << "in " << std::setprecision(2) << elapsed << " s";
  } else {
    s << "ETA " << formatDuration(eta);
  }
  s << (tty_ && !final_line ? "   " : "\n");
  std::fputs(s.str().c_str(), stderr);
  std::fflush(stderr);
}

void writeJson(const std::string& path, const nlohmann::ordered_json& json) {
  std::ofstream out(path, std::ios::trunc);
  out << json.dump(2) << "\n";
  out.close();
  if (!out) throw std::runtime_error(path + ": cannot write");
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

std::string stripSlash(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

double parseNumber(const std::string& flag, const char* text) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (errno || end == text || *end || !std::isfinite(v)) {
    throw std::invalid_argument(flag + ": not a number: '" + text + "'");
  }
  return v;
}

long parseInteger(const std::string& flag, const char* text, long min_value) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text, &end, 10);
  if (errno || end == text || *end || v < min_value) {
    throw std::invalid_argument(flag + ": not a whole number >= " + std::to_string(min_value) +
                                ": '" + text + "'");
  }
  return v;
}

std::string wrapText(const std::string& text, std::size_t width) {
  std::istringstream words(text);
  std::string word;
  std::string out;
  std::size_t line = 0;
  while (words >> word) {
    if (line > 0 && line + 1 + word.size() > width) {
      out += "\n";
      line = 0;
    } else if (line > 0) {
      out += " ";
      ++line;
    }
    out += word;
    line += word.size();
  }
  return out;
}

std::string longName(const std::string& names) {
  const std::size_t comma = names.find_last_of(',');
  return comma == std::string::npos ? names : names.substr(comma + 1);
}

CLI::Option* addNumber(CLI::App* app, const std::string& names, double* value,
                       const std::string& help) {
  const std::string flag = longName(names);
  std::ostringstream shown;
  shown << *value;
  return app
      ->add_option_function<std::string>(
          names,
          [flag, value](const std::string& text) { *value = parseNumber(flag, text.c_str()); },
          help)
      ->type_name("NUM")
      ->default_str(shown.str());
}

int runTool(CLI::App* app, int argc, char** argv, const std::function<int()>& run) {
  const std::string name = app->get_name();
  try {
    try {
      app->parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
      std::cout << app->help();
      return 0;
    } catch (const CLI::ParseError& e) {
      std::cerr << name << ": error: " << e.what() << "\n" << app->help();
      return 2;
    }
    return run();
  } catch (const std::exception& e) {
    std::cerr << name << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace wavog_tools
