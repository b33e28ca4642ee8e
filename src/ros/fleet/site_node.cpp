// wavog_site: a site's coarse layers from its region shards (issue 36). Subscribes to
// <shard>/map_scale_<s> of every shard in ~shards and every scale in ~scales, and publishes their
// union as site_map_scale_<s> (latched; site_layers.h) at ~rate Hz when a shard's layer changed,
// so that a dispatcher sees the whole site without the fine grid of all of it. It also follows
// each shard's <shard>/wavog_fleet/fleet_status and warns (throttled, per vehicle) about a vehicle
// whose latest scan reached no shard's region: outside every region, its scans are mapped by no
// shard (each shard counts them, VehicleStatus.outside_region). Bad parameters
// fail at start-up, naming the parameter; layers that do not fit together are warned (throttled)
// and not published.
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "site_layers.h"
#include "wavog_mapping/FleetStatus.h"

namespace {

struct Scale {
  int scale = 0;
  ros::Publisher pub;
  std::vector<ros::Subscriber> subs;
  std::vector<nav_msgs::OccupancyGrid::ConstPtr> latest;  ///< per shard
  bool changed = false;
};

[[noreturn]] void fail(const std::string& text) {
  ROS_FATAL("wavog_site: %s", text.c_str());
  throw std::invalid_argument(text);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "wavog_site");
  ros::NodeHandle nh, pnh("~");
  std::vector<std::string> shards;
  std::vector<int> scales;
  double rate = 1.0;
  try {
    if (!pnh.getParam("shards", shards) || shards.empty()) {
      fail("~shards must list the shards' namespaces (at least one)");
    }
    if (!pnh.getParam("scales", scales) || scales.empty()) {
      fail("~scales must list the scales to assemble (each in [1, 12], published by every shard "
           "in publish_scales)");
    }
    for (int s : scales) {
      if (s < 1 || s > 12) fail("~scales entry (" + std::to_string(s) + ") must be in [1, 12]");
    }
    pnh.param("rate", rate, 1.0);
    if (!(rate > 0.0 && rate <= 100.0)) {
      fail("~rate (" + std::to_string(rate) + ") must be in (0, 100] Hz");
    }
  } catch (const std::invalid_argument&) {
    return 1;
  }
  std::map<int, Scale> layers;
  for (int s : scales) {
    Scale& l = layers[s];
    l.scale = s;
    l.latest.resize(shards.size());
    l.pub = nh.advertise<nav_msgs::OccupancyGrid>("site_map_scale_" + std::to_string(s), 1, true);
    for (std::size_t i = 0; i < shards.size(); ++i) {
      const std::string topic =
          ros::names::append(shards[i], "map_scale_" + std::to_string(s));
      l.subs.push_back(nh.subscribe<nav_msgs::OccupancyGrid>(
          topic, 2, [&l, i](const nav_msgs::OccupancyGrid::ConstPtr& m) {
            l.latest[i] = m;
            l.changed = true;
          }));
    }
  }
  // Per shard, the latest ~fleet_status.
  std::vector<wavog_mapping::FleetStatus::ConstPtr> statuses(shards.size());
  std::vector<ros::Subscriber> status_subs;
  for (std::size_t i = 0; i < shards.size(); ++i) {
    status_subs.push_back(nh.subscribe<wavog_mapping::FleetStatus>(
        ros::names::append(shards[i], "wavog_fleet/fleet_status"), 2,
        [&statuses, i](const wavog_mapping::FleetStatus::ConstPtr& m) { statuses[i] = m; }));
  }
  std::map<std::string, ros::WallTime> warned;
  ros::WallTimer status_timer = nh.createWallTimer(ros::WallDuration(1.0), [&](const ros::WallTimerEvent&) {
    std::map<std::string, int> in, seen;
    std::map<std::string, std::string> counts;
    for (std::size_t i = 0; i < shards.size(); ++i) {
      if (!statuses[i]) return;  // not every shard heard from yet
      for (const auto& v : statuses[i]->vehicles) {
        if (v.integrated == 0 || v.stale) continue;
        ++seen[v.vehicle];
        in[v.vehicle] += v.in_region ? 1 : 0;
        counts[v.vehicle] += " " + shards[i] + ": " + std::to_string(v.outside_region);
      }
    }
    const ros::WallTime now = ros::WallTime::now();
    for (const auto& kv : seen) {
      if (kv.second != static_cast<int>(shards.size()) || in[kv.first] > 0) continue;
      auto it = warned.find(kv.first);
      if (it != warned.end() && (now - it->second).toSec() < 5.0) continue;
      warned[kv.first] = now;
      ROS_WARN("wavog_site: vehicle '%s' is outside every region: its latest scan reached no "
               "shard, its scans there are mapped by none (outside_region per shard:%s)",
               kv.first.c_str(), counts[kv.first].c_str());
    }
  });
  ros::WallTimer timer = nh.createWallTimer(ros::WallDuration(1.0 / rate), [&](const ros::WallTimerEvent&) {
    for (auto& kv : layers) {
      Scale& l = kv.second;
      if (!l.changed) continue;
      l.changed = false;
      std::vector<const nav_msgs::OccupancyGrid*> parts;
      for (const auto& m : l.latest) parts.push_back(m.get());
      nav_msgs::OccupancyGrid out;
      std::string why;
      if (!wavog_fleet::assembleSiteLayer(parts, &out, &why)) {
        ROS_WARN_THROTTLE(5.0, "wavog_site: site_map_scale_%d not published: %s", l.scale,
                          why.c_str());
        continue;
      }
      l.pub.publish(out);
    }
  });
  ROS_INFO("wavog_site: assembling %zu scales of %zu shards", layers.size(), shards.size());
  ros::spin();
  return 0;
}
