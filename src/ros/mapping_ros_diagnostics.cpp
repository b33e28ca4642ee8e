// MappingRos's /diagnostics: one status per input (received, stale, integrating; every counter of
// the table in input_status.h) and one for the mapper (tf failures, keeping up, map size).
#include <ros/master.h>

#include <algorithm>

#include "mapping_ros_impl.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {
namespace {

/// An input is stale after this many expected periods without a scan (or as many seconds when
/// no rate is expected), and never sooner than kMinStaleSeconds.
constexpr double kStalePeriods = 5.0;
constexpr double kMinStaleSeconds = 0.5;
/// Integration busier than this fraction of the expected scan rate cannot keep up.
constexpr double kBusyFraction = 0.8;

}  // namespace

void MappingRos::Impl::diagnoseInput(const Input* in,
                                     diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const InputCounters& c = in->c;
  const double since = secondsBetween(ros::Time::now(), c.last_receipt);
  const double expected = in->config.expected_rate;
  const double stale_after = expected > 0.0 ? kStalePeriods / expected : kStalePeriods;
  const std::uint64_t new_lost = c[Counter::kLost] - in->lost_reported;
  in->lost_reported = c[Counter::kLost];
  if (new_lost > 0) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                  "%llu scans lost since last report (subscriber queue overflow: the node is "
                  "slower than the input)",
                  static_cast<unsigned long long>(new_lost));
  } else if (c[Counter::kReceived] == 0) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scan received yet");
  } else if (since > std::max(stale_after, kMinStaleSeconds)) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "stale: no scan for %.1f s", since);
  } else if (c[Counter::kIntegrated] == 0) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "scans received but none integrated");
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "integrating");
  }
  addCounters(c, &stat);
  stat.add("measured rate (Hz)", c.rate);
  stat.add("expected rate (Hz)", expected);
}

void MappingRos::Impl::warnSilentInputs() {
  std::string silent;
  bool all_received = true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& in : inputs_) {
      if (in->c[Counter::kReceived] > 0) continue;
      all_received = false;
      if (in->sub.getNumPublishers() == 0) silent += (silent.empty() ? "" : ", ") + in->topic;
    }
  }
  if (all_received) {
    silent_timer_.stop();
    return;
  }
  if (silent.empty()) return;  // publishers there, nothing sent yet: nothing to say
  // The master, outside the lock.
  ros::master::V_TopicInfo topics;
  std::string lasers;
  if (ros::master::getTopics(topics)) {
    for (const auto& t : topics) {
      if (t.datatype == "sensor_msgs/LaserScan") lasers += (lasers.empty() ? "" : ", ") + t.name;
    }
  }
  ROS_WARN(
      "%s: no scan received on %s: nothing publishes it. LaserScan topics advertised: %s; "
      "remap the input (e.g. scan:=<topic>) or list the topic in inputs",
      pnh_.getNamespace().c_str(), silent.c_str(), lasers.empty() ? "none" : lasers.c_str());
}

void MappingRos::Impl::diagnoseMapper(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::uint64_t tf_failures = 0;
  double expected_total = 0.0;
  for (const auto& in : inputs_) {
    tf_failures += in->c.tfFailures();
    expected_total += in->config.expected_rate;
  }
  const std::uint64_t new_failures = tf_failures - tf_failures_reported_;
  tf_failures_reported_ = tf_failures;
  if (new_failures > 0) {
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%llu tf failures since last report",
                  static_cast<unsigned long long>(new_failures));
  } else if (expected_total > 0.0 && last_mean_ * expected_total > kBusyFraction) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 "integration cannot keep up with the expected scan rate");
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "ok");
  }
  stat.add("tf failures", tf_failures);
  stat.add("clock jumps", clock_jumps_);
  stat.add("exceptions caught", exceptions_);
  stat.add("layers refused (too large)", layers_refused_);
  stat.add("transforms refused", tf_refused_);
  stat.add("integration time mean (s)", last_mean_);
  stat.add("integration time max (s)", last_max_);
  stat.add("publish time (s)", publish_time_);
  const wavog::MapStats ms = map_.stats();
  stat.add("blocks", ms.blocks);
  stat.add("nodes", ms.nodes);
  stat.add("tiles", ms.tiles);
  stat.add("bytes", ms.bytes);
}

}  // namespace wavog_ros
