// wavog_log2bag: converts a CARMEN log (plain or gzip) into a rosbag that `rosbag play` can replay:
// sensor_msgs/LaserScan per laser (REP 117: no return as +inf), /tf (map -> base_link from the
// corrected poses, or odom -> base_link from the odometry) and a latched /tf_static
// (base_link -> laser), all with strictly increasing stamps. Written with the rosbag C++ API.
#include <geometry_msgs/TransformStamped.h>
#include <getopt.h>
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

void usage(std::FILE* out) {
  std::fprintf(
      out,
      "Usage: wavog_log2bag [options] LOG OUTPUT.bag\n"
      "Converts a CARMEN log (FLASER, RLASER, ROBOTLASER1; plain or .gz) into a rosbag:\n"
      "/front_laser/scan, /rear_laser/scan (sensor_msgs/LaserScan), /tf, /tf_static.\n\n"
      "  --max-scans N       convert the first N scans only (0: all; default 0)\n"
      "  --strict            a malformed line is fatal (default: report file:line, skip)\n"
      "  --odom              /tf odom -> base_link from the raw odometry (default:\n"
      "                      map -> base_link from the corrected poses)\n"
      "  --stamp ipc|logger  which time stamp of the log to use (default ipc)\n"
      "  --rate HZ           rate used to synthesise missing (zero) stamps (default 10)\n"
      "  --epoch S           relative stamps are shifted to start here (default 1.6e9)\n"
      "  --range-min M       range_min of the scans (default 0)\n"
      "  --compression none|bz2|lz4  bag chunk compression (default none)\n"
      "  --pad S             S seconds of bag time before the first scan (only /tf_static)\n"
      "                      and after the last (the last pose held on /tf), so that\n"
      "                      `rosbag play` subscribers connect in time, the last scan's tf\n"
      "                      is complete, and nodes can be queried before play exits\n"
      "  --quiet             only errors\n"
      "  -h, --help\n");
}

bool parseOptions(int argc, char** argv, Options* o) {
  enum {
    kMax = 1000,
    kStrict,
    kOdom,
    kStamp,
    kRate,
    kEpoch,
    kRangeMin,
    kCompression,
    kPad,
    kQuiet
  };
  const option longopts[] = {{"max-scans", required_argument, nullptr, kMax},
                             {"strict", no_argument, nullptr, kStrict},
                             {"odom", no_argument, nullptr, kOdom},
                             {"stamp", required_argument, nullptr, kStamp},
                             {"rate", required_argument, nullptr, kRate},
                             {"epoch", required_argument, nullptr, kEpoch},
                             {"range-min", required_argument, nullptr, kRangeMin},
                             {"compression", required_argument, nullptr, kCompression},
                             {"pad", required_argument, nullptr, kPad},
                             {"quiet", no_argument, nullptr, kQuiet},
                             {"help", no_argument, nullptr, 'h'},
                             {nullptr, 0, nullptr, 0}};
  int c = 0;
  while ((c = getopt_long(argc, argv, "h", longopts, nullptr)) != -1) {
    switch (c) {
      case kMax:
        o->max_scans = static_cast<std::size_t>(wavog_tools::parseInteger("--max-scans", optarg, 0));
        break;
      case kStrict:
        o->strict = true;
        break;
      case kOdom:
        o->odom = true;
        break;
      case kStamp:
        if (std::string(optarg) != "ipc" && std::string(optarg) != "logger") {
          throw std::invalid_argument("--stamp must be ipc or logger, not '" + std::string(optarg) +
                                      "'");
        }
        o->logger_stamp = std::string(optarg) == "logger";
        break;
      case kRate:
        o->rate = wavog_tools::parseNumber("--rate", optarg);
        break;
      case kEpoch:
        o->epoch = wavog_tools::parseNumber("--epoch", optarg);
        break;
      case kRangeMin:
        o->range_min = wavog_tools::parseNumber("--range-min", optarg);
        break;
      case kCompression:
        o->compression = optarg;
        break;
      case kPad:
        o->pad = wavog_tools::parseNumber("--pad", optarg);
        break;
      case kQuiet:
        o->quiet = true;
        break;
      case 'h':
        usage(stdout);
        std::exit(0);
      default:
        return false;
    }
  }
  if (argc - optind != 2) return false;
  o->log = argv[optind];
  o->bag = argv[optind + 1];
  if (!(o->rate > 0.0) || !std::isfinite(o->rate))
    throw std::invalid_argument("--rate must be > 0");
  if (!(o->pad >= 0.0) || o->pad > 3600.0)
    throw std::invalid_argument("--pad must be in [0, 3600]");
  if (!(o->range_min >= 0.0)) throw std::invalid_argument("--range-min must be >= 0");
  if (o->compression != "none" && o->compression != "bz2" && o->compression != "lz4") {
    throw std::invalid_argument("--compression must be none, bz2 or lz4");
  }
  return true;
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

sensor_msgs::LaserScan toLaserScan(const wavog::CarmenScan& scan, const std::string& frame,
                                   const ros::Time& stamp, double range_min) {
  sensor_msgs::LaserScan msg;
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

int run(const Options& o) {
  const wavog_tools::CarmenLogPlan plan = wavog_tools::planCarmenLog(o.log);
  if (plan.scans_used == 0 && plan.read_error.empty()) {
    std::cerr << "wavog_log2bag: " << o.log << ": no FLASER, RLASER or ROBOTLASER1 scan found\n";
    return 1;
  }
  rosbag::Bag bag;
  bag.open(o.bag, rosbag::bagmode::Write);
  if (o.compression == "bz2") bag.setCompression(rosbag::compression::BZ2);
  if (o.compression == "lz4") bag.setCompression(rosbag::compression::LZ4);

  const std::string fixed_frame = o.odom ? "odom" : "map";
  const std::string base_frame = "base_link";
  wavog::CarmenReader reader(o.log, o.strict);
  wavog_tools::StampRepair stamps(o.rate, o.epoch);
  std::map<std::string, std::size_t> per_topic;
  std::size_t written = 0;
  std::size_t tf_messages = 0;
  std::size_t reported_errors = 0;
  bool static_written = false;
  ros::Time last_stamp;
  wavog::Pose2 last_base;
  // One latched message with every laser mount, so that `rosbag play` re-latches it.
  auto write_static = [&](const ros::Time& stamp) {
    tf2_msgs::TFMessage statics;
    for (const auto& l : plan.lasers) {
      if (l.used) statics.transforms.push_back(toTransform(base_frame, l.frame, l.mount, stamp));
    }
    auto header = boost::make_shared<ros::M_string>();
    // A custom connection header replaces rosbag's own: it must carry the type fields too.
    (*header)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
    (*header)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
    (*header)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
    (*header)["callerid"] = "/wavog_log2bag";
    (*header)["latching"] = "1";
    bag.write("/tf_static", stamp, statics, header);
  };
  std::string fatal;
  wavog::CarmenScan scan;
  try {
    while ((o.max_scans == 0 || written < o.max_scans) && reader.next(&scan)) {
      for (; reported_errors < reader.errors().size(); ++reported_errors) {
        std::cerr << "wavog_log2bag: skipped malformed line: " << reader.errors()[reported_errors]
                  << "\n";
      }
      const wavog_tools::CarmenLaser* laser = plan.laserFor(scan.type);
      if (laser == nullptr) continue;
      const double raw = o.logger_stamp ? scan.logger_timestamp : scan.ipc_timestamp;
      std::uint32_t sec = 0;
      std::uint32_t nsec = 0;
      wavog_tools::toSecNsec(stamps.repair(raw), &sec, &nsec);
      const ros::Time stamp(sec, nsec);
      if (!static_written) {
        write_static(stamp - ros::Duration(o.pad));
        static_written = true;
      }
      last_stamp = stamp;
      // base_link pose such that base_link * mount is exactly the logged laser pose (corrected),
      // or the robot's odometry pose with --odom.
      const wavog::Pose2 base =
          o.odom ? scan.robot_pose
                 : wavog_tools::compose(scan.laser_pose, wavog_tools::inverse(laser->mount));
      last_base = base;
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(toTransform(fixed_frame, base_frame, base, stamp));
      bag.write("/tf", stamp, tf);
      ++tf_messages;
      bag.write(laser->topic, stamp, toLaserScan(scan, laser->frame, stamp, o.range_min));
      ++per_topic[laser->topic];
      ++written;
    }
  } catch (const wavog::CarmenParseError& e) {
    fatal = std::string(e.what()) + " (--strict)";
  } catch (const std::runtime_error& e) {
    fatal = e.what();
  }
  for (; reported_errors < reader.errors().size(); ++reported_errors) {
    std::cerr << "wavog_log2bag: skipped malformed line: " << reader.errors()[reported_errors]
              << "\n";
  }
  if (static_written && o.pad > 0.0) {
    // The robot holds its last pose through the padding: a node that waits for tf after a scan's
    // stamp (motion compensation) can place the last scan too.
    const ros::Time end = last_stamp + ros::Duration(o.pad);
    for (const ros::Time& t : {last_stamp + ros::Duration(std::min(o.pad, kHoldStep)), end}) {
      tf2_msgs::TFMessage tf;
      tf.transforms.push_back(toTransform(fixed_frame, base_frame, last_base, t));
      bag.write("/tf", t, tf);
      ++tf_messages;
    }
    write_static(end);
  }
  bag.close();
  if (!fatal.empty() && o.strict) {
    std::filesystem::remove(o.bag);
    std::cerr << "wavog_log2bag: error: " << fatal << "; no bag written\n";
    return 1;
  }
  if (!o.quiet) {
    std::cerr << "wavog_log2bag: wrote " << o.bag << ": " << written << " scans";
    for (const auto& [topic, n] : per_topic) std::cerr << ", " << n << " on " << topic;
    std::cerr << ", " << tf_messages << " on /tf (" << fixed_frame << " -> " << base_frame << "), "
              << (o.pad > 0.0 ? 2 : 1) << " on /tf_static\n";
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
  if (!fatal.empty()) {
    std::cerr << "wavog_log2bag: error: " << fatal << "; the bag holds the " << written
              << " scans read before it\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  return wavog_tools::toolMain(
      "wavog_log2bag", [&] { return parseOptions(argc, argv, &options); }, usage,
      [&] {
        ros::Time::init();
        return run(options);
      });
}
