// wavog_log2bag: converts a CARMEN log (plain or gzip) into a rosbag that `rosbag play` can replay:
// sensor_msgs/LaserScan per laser (REP 117: no return as +inf), /tf (map -> base_link from the
// corrected poses, or odom -> base_link from the odometry) and a latched /tf_static
// (base_link -> laser), all with strictly increasing stamps. Written with the rosbag C++ API.
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <string>

#include "tool_support.h"
#include "wavog_mapping/io/carmen_reader.h"

namespace {

constexpr double kDefaultEpoch = 1.6e9;  // 2020-09-13: where relative log times start
constexpr double kDefaultRate = 10.0;    // Hz, for synthesised stamps
constexpr double kHoldStep = 0.5;        // s after the last scan: first /tf of the held pose

struct Options {
  std::string log;
  std::string bag;
  std::size_t max_scans = 0;
  bool strict = false;
  bool odom = false;
  bool logger_stamp = false;
  double rate = kDefaultRate;
  double epoch = kDefaultEpoch;
  double range_min = 0.0;
  std::string compression = "none";
  double pad = 0.0;
  bool quiet = false;
};

/// What --help says first.
constexpr const char* kDescription =
    "Converts a CARMEN log (FLASER, RLASER, ROBOTLASER1; plain or .gz) into a rosbag: "
    "/front_laser/scan, /rear_laser/scan (sensor_msgs/LaserScan), /tf, /tf_static.";

/// The command line of wavog_log2bag (its --help is generated from these).
void addOptions(CLI::App* app, Options* o) {
  wavog_tools::addInteger(app, "--max-scans", &o->max_scans, 0,
                          "convert the first N scans only (0: all)");
  app->add_flag("--strict", o->strict,
                "a malformed line is fatal (default: report file:line, skip)");
  app->add_flag("--odom", o->odom,
                "/tf odom -> base_link from the raw odometry (default: map -> base_link from the "
                "corrected poses)");
  app->add_option_function<std::string>(
      "--stamp",
      [o](const std::string& v) {
        if (v != "ipc" && v != "logger") {
          throw std::invalid_argument("--stamp must be ipc or logger, not '" + v + "'");
        }
        o->logger_stamp = v == "logger";
      },
      "ipc|logger: which time stamp of the log to use (default ipc)");
  wavog_tools::addNumber(app, "--rate", &o->rate,
                         "rate (Hz) used to synthesise missing (zero) stamps");
  wavog_tools::addNumber(app, "--epoch", &o->epoch,
                         "relative stamps are shifted to start here (s)");
  wavog_tools::addNumber(app, "--range-min", &o->range_min, "range_min of the scans (m)");
  app->add_option("--compression", o->compression, "none|bz2|lz4: bag chunk compression")
      ->capture_default_str();
  wavog_tools::addNumber(app, "--pad", &o->pad,
                         "S seconds of bag time before the first scan (only /tf_static) and after "
                         "the last (the last pose held on /tf), so that `rosbag play` subscribers "
                         "connect in time, the last scan's tf is complete, and nodes can be "
                         "queried before play exits");
  app->add_flag("--quiet", o->quiet, "only errors");
  app->add_option("log", o->log, "CARMEN log (FLASER, RLASER, ROBOTLASER1; plain or .gz)")
      ->required();
  app->add_option("bag", o->bag, "output rosbag")->required();
}

/// The checks of the values that need more than a number.
void validate(const Options& o) {
  if (!(o.rate > 0.0) || !std::isfinite(o.rate)) throw std::invalid_argument("--rate must be > 0");
  if (!(o.pad >= 0.0) || o.pad > 3600.0) throw std::invalid_argument("--pad must be in [0, 3600]");
  if (!(o.range_min >= 0.0)) throw std::invalid_argument("--range-min must be >= 0");
  if (o.compression != "none" && o.compression != "bz2" && o.compression != "lz4") {
    throw std::invalid_argument("--compression must be none, bz2 or lz4");
  }
}

geometry_msgs::TransformStamped toTransform(const std::string& parent, const std::string& child,
                                            const wavog::Pose2& p, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = p.x;
  t.transform.translation.y = p.y;
  t.transform.translation.z = 0.0;
  t.transform.rotation.z = std::sin(p.theta / 2.0);
  t.transform.rotation.w = std::cos(p.theta / 2.0);
  return t;
}

// `seq`: the scan's number on its topic (from 1), so that a node can count the scans it never got.
sensor_msgs::LaserScan toLaserScan(const wavog::CarmenScan& scan, const std::string& frame,
                                   const ros::Time& stamp, double range_min, std::uint32_t seq) {
  sensor_msgs::LaserScan msg;
  msg.header.seq = seq;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.angle_min = static_cast<float>(scan.angle_min);
  msg.angle_increment = static_cast<float>(scan.angle_increment);
  msg.angle_max = static_cast<float>(
      scan.angle_min + scan.angle_increment * static_cast<double>(scan.ranges.size() - 1));
  msg.time_increment = 0.0f;  // CARMEN logs do not time the beams: one pose per scan
  msg.scan_time = 0.0f;
  msg.range_min = static_cast<float>(range_min);
  msg.range_max = static_cast<float>(scan.range_max);
  msg.ranges.resize(scan.ranges.size());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const float r = scan.ranges[i];
    msg.ranges[i] = scan.isNoReturn(r) ? std::numeric_limits<float>::infinity() : r;
  }
  return msg;
}

/// The bag being written: one /tf and one LaserScan per scan, the latched /tf_static at the start
/// and the end, and the counts for the final report.
class BagWriter {
 public:
  BagWriter(const Options& o, const wavog_tools::CarmenLogPlan& plan)
      : o_(o), plan_(plan), fixed_frame_(o.odom ? "odom" : "map") {
    bag_.open(o.bag, rosbag::bagmode::Write);
    if (o.compression == "bz2") bag_.setCompression(rosbag::compression::BZ2);
    if (o.compression == "lz4") bag_.setCompression(rosbag::compression::LZ4);
  }

  std::size_t written() const { return written_; }

  void writeScan(const wavog::CarmenScan& scan, const wavog_tools::CarmenLaser& laser,
                 const ros::Time& stamp) {
    if (!static_written_) {
      writeStatic(stamp - ros::Duration(o_.pad));
      static_written_ = true;
    }
    last_stamp_ = stamp;
    // base_link pose such that base_link * mount is exactly the logged laser pose (corrected),
    // or the robot's odometry pose with --odom.
    last_base_ = o_.odom ? scan.robot_pose
                         : wavog_tools::compose(scan.laser_pose, wavog_tools::inverse(laser.mount));
    writeTf(last_base_, stamp);
    const auto seq = static_cast<std::uint32_t>(++per_topic_[laser.topic]);
    bag_.write(laser.topic, stamp, toLaserScan(scan, laser.frame, stamp, o_.range_min, seq));
    ++written_;
  }

  /// The robot holds its last pose through the padding: a node that waits for tf after a scan's
  /// stamp (motion compensation) can place the last scan too. Then the bag is closed.
  void finish() {
    if (static_written_ && o_.pad > 0.0) {
      const ros::Time end = last_stamp_ + ros::Duration(o_.pad);
      writeTf(last_base_, last_stamp_ + ros::Duration(std::min(o_.pad, kHoldStep)));
      writeTf(last_base_, end);
      writeStatic(end);
    }
    bag_.close();
  }

  void report() const {
    std::cerr << "wavog_log2bag: wrote " << o_.bag << ": " << written_ << " scans";
    for (const auto& [topic, n] : per_topic_) std::cerr << ", " << n << " on " << topic;
    std::cerr << ", " << tf_messages_ << " on /tf (" << fixed_frame_ << " -> " << kBaseFrame
              << "), " << (o_.pad > 0.0 ? 2 : 1) << " on /tf_static\n";
  }

 private:
  static constexpr const char* kBaseFrame = "base_link";

  void writeTf(const wavog::Pose2& base, const ros::Time& stamp) {
    tf2_msgs::TFMessage tf;
    tf.transforms.push_back(toTransform(fixed_frame_, kBaseFrame, base, stamp));
    bag_.write("/tf", stamp, tf);
    ++tf_messages_;
  }

  /// One latched message with every laser mount, so that `rosbag play` re-latches it.
  void writeStatic(const ros::Time& stamp) {
    tf2_msgs::TFMessage statics;
    for (const auto& l : plan_.lasers) {
      if (l.used) statics.transforms.push_back(toTransform(kBaseFrame, l.frame, l.mount, stamp));
    }
    auto header = boost::make_shared<ros::M_string>();
    // A custom connection header replaces rosbag's own: it must carry the type fields too.
    (*header)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
    (*header)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
    (*header)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
    (*header)["callerid"] = "/wavog_log2bag";
    (*header)["latching"] = "1";
    bag_.write("/tf_static", stamp, statics, header);
  }

  const Options& o_;
  const wavog_tools::CarmenLogPlan& plan_;
  const std::string fixed_frame_;
  rosbag::Bag bag_;
  std::map<std::string, std::size_t> per_topic_;
  std::size_t written_ = 0;
  std::size_t tf_messages_ = 0;
  bool static_written_ = false;
  ros::Time last_stamp_;
  wavog::Pose2 last_base_;
};

/// The notes of the end-of-run report: identity mounts, skipped duplicates, stamp repairs,
/// malformed lines.
void reportNotes(const wavog_tools::CarmenLogPlan& plan, const wavog_tools::StampRepair& stamps,
                 const wavog::CarmenReader& reader) {
  for (const auto& l : plan.lasers) {
    if (l.used && !l.mount_from_log) {
      std::cerr << "wavog_log2bag: " << l.type << ": the log's robot pose is not in the laser "
                << "pose's frame; base_link -> " << l.frame << " set to identity\n";
    }
  }
  if (plan.skipped_duplicates > 0) {
    std::cerr << "wavog_log2bag: " << plan.skipped_duplicates
              << " ROBOTLASER1 scans skipped: the log's FLASER lines hold the same laser\n";
  }
  for (const auto& line : stamps.report()) std::cerr << "wavog_log2bag: " << line << "\n";
  if (!reader.errors().empty()) {
    std::cerr << "wavog_log2bag: " << reader.errors().size() << " malformed line(s) skipped\n";
  }
}

int run(const Options& o) {
  validate(o);
  ros::Time::init();
  const wavog_tools::CarmenLogPlan plan = wavog_tools::planCarmenLog(o.log);
  if (plan.scans_used == 0 && plan.read_error.empty()) {
    std::cerr << "wavog_log2bag: " << o.log << ": no FLASER, RLASER or ROBOTLASER1 scan found\n";
    return 1;
  }
  BagWriter bag(o, plan);
  wavog::CarmenReader reader(o.log, o.strict);
  wavog_tools::StampRepair stamps(o.rate, o.epoch);
  std::size_t reported_errors = 0;
  auto report_errors = [&] {
    for (; reported_errors < reader.errors().size(); ++reported_errors) {
      std::cerr << "wavog_log2bag: skipped malformed line: " << reader.errors()[reported_errors]
                << "\n";
    }
  };
  std::string fatal;
  wavog::CarmenScan scan;
  try {
    while ((o.max_scans == 0 || bag.written() < o.max_scans) && reader.next(&scan)) {
      report_errors();
      const wavog_tools::CarmenLaser* laser = plan.laserFor(scan.type);
      if (laser == nullptr) continue;
      std::uint32_t sec = 0;
      std::uint32_t nsec = 0;
      wavog_tools::toSecNsec(
          stamps.repair(o.logger_stamp ? scan.logger_timestamp : scan.ipc_timestamp), &sec, &nsec);
      bag.writeScan(scan, *laser, ros::Time(sec, nsec));
    }
  } catch (const wavog::CarmenParseError& e) {
    fatal = std::string(e.what()) + " (--strict)";
  } catch (const std::runtime_error& e) {
    fatal = e.what();
  }
  report_errors();
  bag.finish();
  if (!fatal.empty() && o.strict) {
    std::filesystem::remove(o.bag);
    std::cerr << "wavog_log2bag: error: " << fatal << "; no bag written\n";
    return 1;
  }
  if (!o.quiet) {
    bag.report();
    reportNotes(plan, stamps, reader);
  }
  if (!fatal.empty()) {
    std::cerr << "wavog_log2bag: error: " << fatal << "; the bag holds the " << bag.written()
              << " scans read before it\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return wavog_tools::toolMain(argc, argv, "wavog_log2bag", kDescription, addOptions, run);
}
