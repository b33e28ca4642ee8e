// wavog_offline's input readers: a rosbag (tf into a tf2::BufferCore, scans placed by the shared
// placeScan) or a CARMEN log (the logged poses as they are), both into one Session.
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "offline.h"
#include "wavog_mapping/core/motion_compensation.h"
#include "wavog_mapping/core/scan_period.h"
#include "wavog_mapping/io/carmen_reader.h"
#include "wavog_mapping/ros/conversions.h"
#include "wavog_mapping/ros/pose_check.h"
#include "wavog_mapping/ros/scan_placement.h"

namespace wavog_offline {
namespace {

constexpr double kTfCacheMargin = 60.0;  // s added to the bag's duration for the tf buffer

std::string describeBagTopics(const rosbag::Bag& bag) {
  rosbag::View all(bag);
  std::map<std::string, std::pair<std::string, std::size_t>> topics;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    topics[c->topic].first = c->datatype;
  }
  for (const auto& [topic, info] : topics) {
    rosbag::View one(bag, rosbag::TopicQuery(topic));
    topics[topic].second = one.size();
  }
  std::ostringstream s;
  for (const auto& [topic, info] : topics) {
    s << "\n  " << topic << " (" << info.first << ", " << info.second << " msgs)";
  }
  return topics.empty() ? std::string("\n  (no topics)") : s.str();
}

// --laser-parent / --laser-pose: the transform laser_parent <- frame, static (valid at any time).
geometry_msgs::TransformStamped laserMount(const Options& o, const std::string& frame) {
  std::vector<double> v = o.laser_pose;
  if (v.empty()) v.assign(6, 0.0);
  geometry_msgs::TransformStamped t;
  t.header.frame_id = o.laser_parent;
  t.child_frame_id = frame;
  t.transform.translation.x = v[0];
  t.transform.translation.y = v[1];
  t.transform.translation.z = v[2];
  tf2::Quaternion q;
  q.setRPY(v[5], v[4], v[3]);  // roll, pitch, yaw
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

std::string normaliseTopic(const std::string& t) { return t.empty() || t[0] == '/' ? t : "/" + t; }

}  // namespace

bool isBag(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[9] = {0};
  in.read(head, 8);
  return std::string(head, 8) == "#ROSBAG ";
}

InputInfo runBag(const Options& o, const wavog_ros::Config& config,
                 std::unique_ptr<Session>* session) {
  InputInfo info;
  info.type = "bag";
  info.fixed_frame =
      o.fixed_frame.empty() ? wavog_tools::stripSlash(config.ros.map_frame) : o.fixed_frame;
  rosbag::Bag bag;
  try {
    bag.open(o.input, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(o.input + ": cannot read the bag: " + e.what());
  }

  // Scan topics: asked for, or every LaserScan topic of the bag.
  std::map<std::string, std::string> bag_topics;  // normalised name -> name in the bag
  std::vector<std::string> laser_topics;
  {
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      bag_topics[normaliseTopic(c->topic)] = c->topic;
      if (c->datatype == "sensor_msgs/LaserScan" &&
          std::find(laser_topics.begin(), laser_topics.end(), c->topic) == laser_topics.end()) {
        laser_topics.push_back(c->topic);
      }
    }
  }
  std::vector<std::string> wanted = o.topics;
  if (wanted.empty() && !o.config.empty()) {
    for (const auto& input : config.ros.inputs) wanted.push_back(input.topic);
  }
  if (wanted.empty()) {
    if (laser_topics.empty()) {
      throw std::runtime_error(o.input + ": the bag has no sensor_msgs/LaserScan topic; it has:" +
                               describeBagTopics(bag));
    }
    info.topics = laser_topics;
  } else {
    for (const auto& t : wanted) {
      const auto it = bag_topics.find(normaliseTopic(t));
      if (it == bag_topics.end()) {
        throw std::runtime_error(o.input + ": the bag has no topic '" + t +
                                 "' (use --topics); it has:" + describeBagTopics(bag));
      }
      info.topics.push_back(it->second);
    }
  }

  // tf: the whole bag into one buffer first, so each scan sees tf before and after its stamp.
  rosbag::View tf_view(
      bag, rosbag::TopicQuery(std::vector<std::string>{"/tf", "/tf_static", "tf", "tf_static"}));
  const double duration =
      (tf_view.size() > 0) ? (tf_view.getEndTime() - tf_view.getBeginTime()).toSec() : 0.0;
  tf2::BufferCore tf(ros::Duration(duration + kTfCacheMargin));
  std::map<std::string, std::string> bag_parents;  // child frame -> its parent in the bag's tf
  for (const rosbag::MessageInstance& m : tf_view) {
    const auto msg = m.instantiate<tf2_msgs::TFMessage>();
    if (!msg) continue;
    const bool is_static = m.getTopic().find("tf_static") != std::string::npos;
    for (geometry_msgs::TransformStamped t : msg->transforms) {
      t.header.frame_id = wavog_tools::stripSlash(t.header.frame_id);
      t.child_frame_id = wavog_tools::stripSlash(t.child_frame_id);
      bag_parents.emplace(t.child_frame_id, t.header.frame_id);
      tf.setTransform(t, "bag", is_static);
    }
  }
  std::set<std::string> mounted;  // scan frames held at --laser-pose

  rosbag::View scans(bag, rosbag::TopicQuery(info.topics));
  std::size_t total = scans.size();
  if (o.max_scans > 0) total = std::min(total, o.max_scans);
  *session = std::make_unique<Session>(o, config, total);
  Session& s = **session;
  std::string first_tf_error;
  std::set<std::string> scan_frames;
  std::map<std::string, wavog::ScanPeriod> periods;  // per topic, for forget_half_life
  std::set<std::string> slash_warned;                // topics whose frame_id had a leading '/'
  wavog::MotionCompensator compensator;
  // As the node: a scan whose laser would move faster than a vehicle is refused (a corrupt
  // odometry sample), the first refusal's reason goes to the warnings.
  wavog_ros::PoseCheck poses(config.ros.max_sensor_speed);
  std::size_t absurd_poses = 0;
  std::string first_absurd;
  wavog_ros::PlacementOptions placement_options;
  placement_options.fixed_frame = info.fixed_frame;
  placement_options.motion_compensation = config.ros.motion_compensation;
  for (const rosbag::MessageInstance& m : scans) {
    if (s.done() >= total) break;
    const auto scan = m.instantiate<sensor_msgs::LaserScan>();
    if (!scan) {
      s.skip("not_a_laserscan");
      continue;
    }
    // Old bags carry frame ids with a leading '/', which tf2 rejects: strip it, saying so once per
    // topic as the node does (the bag's tf frames were stripped the same way).
    const std::string received = scan->header.frame_id;
    if (wavog_ros::stripFrameSlash(&scan->header.frame_id) &&
        slash_warned.insert(m.getTopic()).second) {
      info.warnings.push_back(m.getTopic() + ": " + wavog_ros::frameSlashWarning(received));
    }
    const std::string& frame = scan->header.frame_id;
    scan_frames.insert(frame);
    if (!o.laser_parent.empty() && !frame.empty() && mounted.insert(frame).second) {
      const auto placed = bag_parents.find(frame);
      if (placed != bag_parents.end()) {
        throw std::runtime_error(o.input + ": the bag's tf already places the scan frame '" +
                                 frame + "' in '" + placed->second +
                                 "': drop --laser-parent / --laser-pose");
      }
      if (frame == o.laser_parent) {
        throw std::runtime_error("--laser-parent '" + o.laser_parent +
                                 "' is the scan frame itself: give the frame the laser is "
                                 "mounted on (e.g. base_link)");
      }
      tf.setTransform(laserMount(o, frame), "--laser-pose", true);
    }
    wavog_ros::DropReason reason = wavog_ros::DropReason::kEmpty;
    if (!wavog_ros::checkScan(*scan, &reason)) {
      s.skip(std::string("scan_") + wavog_ros::toString(reason));
      continue;
    }
    // The node's placement (scan_placement.h): pose at the first and last beam from tf, mirrored
    // view for an upside-down laser, motion compensation over the sweep.
    const wavog_ros::ScanPlacement placement = wavog_ros::placeScan(tf, *scan, placement_options);
    if (!placement.placed()) {
      if (first_tf_error.empty()) first_tf_error = placement.error;
      s.skip(placement.failure == wavog_ros::TfFailure::kExtrapolation ? "tf_extrapolation"
                                                                       : "tf_unavailable");
      continue;
    }
    const double first_beam = scan->header.stamp.toSec();
    const double last_beam =
        first_beam + (placement.compensate ? wavog_ros::sweepSeconds(*scan) : 0.0);
    const std::string absurd =
        poses.check(frame, placement.start, first_beam, placement.end, last_beam);
    if (!absurd.empty()) {
      if (absurd_poses++ == 0) first_absurd = absurd;
      s.skip("absurd_pose");
      continue;
    }
    info.motion_fallbacks += placement.motion_fallback ? 1 : 0;
    info.motion_compensated += placement.compensate ? 1 : 0;
    wavog::Pose2 pose;
    wavog::ScanView view = placement.placedView(*scan, &compensator, &pose);
    view.period = periods[m.getTopic()].next(scan->header.stamp.toSec(), scan->scan_time);
    s.integrate(pose, view, scan->header.stamp.toSec());
  }
  s.finish();
  if (absurd_poses > 0) {
    info.warnings.push_back(std::to_string(absurd_poses) +
                            " scans refused for an absurd pose from tf, the first: " +
                            first_absurd);
  }
  if (!mounted.empty()) {
    std::ostringstream mount;
    mount << o.laser_parent << " <-";
    for (const auto& f : mounted) mount << " " << f;
    mount << ":";
    const std::vector<double> v = o.laser_pose.empty() ? std::vector<double>(6, 0.0) : o.laser_pose;
    for (double x : v) mount << " " << x;
    info.laser_mount = mount.str();
  }
  if (s.integrated() == 0 && !first_tf_error.empty()) {
    std::vector<std::string> frames;
    tf._getFrameStrings(frames);
    std::ostringstream msg;
    msg << o.input << ": tf never connects the scan frame";
    for (const auto& f : scan_frames) msg << " '" << f << "'";
    msg << " to the fixed frame '" << info.fixed_frame << "' (" << first_tf_error
        << ").\n  Frames in the bag's tf: ";
    if (frames.empty()) msg << "none (the bag has no /tf or /tf_static)";
    for (std::size_t i = 0; i < frames.size(); ++i) msg << (i ? ", " : "") << frames[i];
    msg << ".\n  Use --laser-parent <frame> --laser-pose \"x y z yaw pitch roll\" when tf lacks "
           "only the laser's mount, or --fixed-frame <frame> (e.g. the scan frame, to map with "
           "the laser held fixed).";
    throw std::runtime_error(msg.str());
  }
  return info;
}

InputInfo runCarmen(const Options& o, const wavog_ros::Config& config,
                    std::unique_ptr<Session>* session) {
  InputInfo info;
  info.type = "carmen";
  info.fixed_frame = "log";
  const wavog_tools::CarmenLogPlan plan = wavog_tools::planCarmenLog(o.input);
  for (const auto& l : plan.lasers) {
    if (l.used) info.topics.push_back(l.type);
  }
  if (plan.skipped_duplicates > 0) {
    info.warnings.push_back(
        std::to_string(plan.skipped_duplicates) +
        " ROBOTLASER1 scans skipped: the log's FLASER lines hold the same laser");
  }
  std::size_t total = plan.scans_used;
  if (o.max_scans > 0) total = std::min(total, o.max_scans);
  *session = std::make_unique<Session>(o, config, total);
  Session& s = **session;
  wavog::CarmenReader reader(o.input, false);
  wavog::CarmenScan scan;
  std::map<std::string, wavog::ScanPeriod> periods;  // per laser, for forget_half_life
  try {
    // Read on to the end (not just `total` scans), so that a truncated stream is reported.
    while ((o.max_scans == 0 || s.done() < o.max_scans) && reader.next(&scan)) {
      if (plan.laserFor(scan.type) == nullptr) continue;
      wavog::ScanView view = scan.view(0.0);
      view.period = periods[scan.type].next(scan.ipc_timestamp);
      s.integrate(scan.laser_pose, view, scan.ipc_timestamp);
    }
  } catch (const std::runtime_error& e) {
    info.read_error = e.what();
  }
  s.finish();
  for (const auto& e : reader.errors()) {
    info.warnings.push_back("skipped malformed line: " + e);
    s.drop("malformed_line");
  }
  if (total == 0 && info.read_error.empty()) {
    throw std::runtime_error(o.input + ": no FLASER, RLASER or ROBOTLASER1 scan found");
  }
  return info;
}

}  // namespace wavog_offline
