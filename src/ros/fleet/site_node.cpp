// wavog_site: a site's coarse layers from its region shards (issue 36). Subscribes to
// <shard>/map_scale_<s> of every shard in ~shards and every scale in ~scales, and publishes their
// union as site_map_scale_<s> (latched; site_layers.h) at ~rate Hz when a shard's layer changed,
// so that a dispatcher sees the whole site without the fine grid of all of it. It also follows
// each shard's <shard>/wavog_fleet/fleet_status (site_vehicles.h) and warns (throttled, per
// vehicle) about a vehicle whose latest scan reached no shard's region: outside every region, its
// scans are mapped by no shard (also once it is silent); the scans mapped by none stay an upper
// bound when a shard restarts (ShardLives). Bad parameters fail at start-up, naming the parameter
// and its range (site_params.h); shards whose fleet_region parameters overlap are warned about
// once all are known. Layers that cannot be put together are refused (counted by reason, warned
// with a throttle, not published). Counters and the vehicles outside every region go to
// /diagnostics.
#include <diagnostic_updater/diagnostic_updater.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "site_layers.h"
#include "site_params.h"
#include "site_vehicles.h"
#include "wavog_mapping/FleetStatus.h"

namespace {

struct Scale {
  int scale = 0;
  ros::Publisher pub;
  std::vector<ros::Subscriber> subs;
  std::vector<nav_msgs::OccupancyGrid::ConstPtr> latest;  ///< per shard
  bool changed = false;
  std::uint64_t published = 0;
};

// Refusals by reason, over every scale.
struct Refusals {
  std::uint64_t bad_layer = 0, mismatch = 0, too_large = 0;
  std::string last;  ///< the latest refusal's text
};

// Reads every shard's fleet_region; once all are known (true), *overlaps lists the overlapping
// pairs, each warned. A shard not heard from yet (no status) whose parameter is not set: false,
// read again later; one heard from without the parameter has no region.
bool checkRegions(const ros::NodeHandle& nh, const std::vector<std::string>& shards,
                  const std::vector<wavog_mapping::FleetStatus::ConstPtr>& statuses,
                  std::vector<std::string>* overlaps) {
  std::vector<wavog_fleet::ShardRegion> regions;
  for (std::size_t i = 0; i < shards.size(); ++i) {
    const std::string key =
        nh.resolveName(ros::names::append(shards[i], "wavog_fleet/fleet_region"));
    XmlRpc::XmlRpcValue value;
    wavog_fleet::ShardRegion r;
    r.shard = shards[i];
    if (ros::param::get(key, value)) {
      if (!wavog_fleet::readRegion(value, &r.region)) return false;  // the shard refuses it
    } else if (!statuses[i]) {
      return false;
    }
    regions.push_back(r);
  }
  *overlaps = wavog_fleet::overlappingRegions(regions);
  for (const std::string& o : *overlaps) {
    ROS_WARN(
        "wavog_site: the regions of %s overlap: cells there are mapped by both shards (the "
        "site layer takes one); give each shard a fleet_region of its own",
        o.c_str());
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "wavog_site");
  ros::NodeHandle nh, pnh("~");
  std::vector<std::string> shards;
  std::vector<int> scales;
  double rate = 1.0;
  std::uint64_t max_cells = wavog_fleet::kDefaultMaxSiteCells;
  try {
    XmlRpc::XmlRpcValue root;
    if (!pnh.getParam(pnh.getNamespace(), root)) root = XmlRpc::XmlRpcValue();
    const wavog_fleet::SiteParams p = wavog_fleet::readSiteParams(root);
    shards = p.shards;
    scales = p.scales;
    rate = p.rate;
    max_cells = p.max_cells;
  } catch (const std::invalid_argument& e) {
    ROS_FATAL("wavog_site: %s", e.what());
    return 1;
  }
  std::map<int, Scale> layers;
  for (int s : scales) {
    Scale& l = layers[s];
    l.scale = s;
    l.latest.resize(shards.size());
    l.pub = nh.advertise<nav_msgs::OccupancyGrid>("site_map_scale_" + std::to_string(s), 1, true);
    for (std::size_t i = 0; i < shards.size(); ++i) {
      const std::string topic = ros::names::append(shards[i], "map_scale_" + std::to_string(s));
      l.subs.push_back(nh.subscribe<nav_msgs::OccupancyGrid>(
          topic, 2, [&l, i](const nav_msgs::OccupancyGrid::ConstPtr& m) {
            l.latest[i] = m;
            l.changed = true;
          }));
    }
  }
  // Per shard, the latest ~fleet_status.
  // Per shard, the latest ~fleet_status; every status adds to the shards' lives (restarts).
  std::vector<wavog_mapping::FleetStatus::ConstPtr> statuses(shards.size());
  wavog_fleet::ShardLives lives(shards.size());
  std::vector<ros::Subscriber> status_subs;
  for (std::size_t i = 0; i < shards.size(); ++i) {
    status_subs.push_back(nh.subscribe<wavog_mapping::FleetStatus>(
        ros::names::append(shards[i], "wavog_fleet/fleet_status"), 2,
        [&statuses, &lives, i](const wavog_mapping::FleetStatus::ConstPtr& m) {
          statuses[i] = m;
          lives.add(i, *m);
        }));
  }
  // The shards' regions (<shard>/wavog_fleet/fleet_region), read once every shard's is there:
  // overlapping regions warned once, and in /diagnostics.
  std::vector<std::string> overlaps;
  bool regions_read = false;

  wavog_fleet::SiteVehicles site;
  std::map<std::string, ros::WallTime> warned;
  // Topics without a publisher and nothing received kSilentAfter s after start: a shard's
  // namespace or a scale it does not publish (publish_scales) would otherwise leave the site
  // layers silently empty. (A shard with nothing observed in its region yet advertises its
  // layers but sends none: not counted.)
  constexpr double kSilentAfter = 10.0;
  const ros::WallTime started = ros::WallTime::now();
  std::vector<std::string> silent;
  ros::WallTime silent_warned;
  ros::WallTimer status_timer =
      nh.createWallTimer(ros::WallDuration(1.0), [&](const ros::WallTimerEvent&) {
        site = wavog_fleet::summariseVehicles(statuses, shards, lives);
        if (!regions_read) regions_read = checkRegions(nh, shards, statuses, &overlaps);
        const ros::WallTime now = ros::WallTime::now();
        silent.clear();
        for (const auto& kv : layers) {
          for (std::size_t i = 0; i < shards.size(); ++i) {
            if (kv.second.latest[i] || kv.second.subs[i].getNumPublishers() > 0) continue;
            silent.push_back(kv.second.subs[i].getTopic());
          }
        }
        for (std::size_t i = 0; i < shards.size(); ++i) {
          if (statuses[i] || status_subs[i].getNumPublishers() > 0) continue;
          silent.push_back(status_subs[i].getTopic());
        }
        if (!silent.empty() && (now - started).toSec() >= kSilentAfter &&
            (silent_warned.isZero() || (now - silent_warned).toSec() >= 10.0)) {
          silent_warned = now;
          std::string names;
          for (const auto& t : silent) names += " " + t;
          ROS_WARN(
              "wavog_site: no publisher after %.0f s on %zu topics (is each shard's "
              "namespace in ~shards, and each of ~scales in its publish_scales?):%s",
              (now - started).toSec(), silent.size(), names.c_str());
        }
        for (const auto& v : site.outside) {
          auto it = warned.find(v.vehicle);
          if (it != warned.end() && (now - it->second).toSec() < 5.0) continue;
          warned[v.vehicle] = now;
          ROS_WARN(
              "wavog_site: vehicle '%s' is outside every region%s: its latest scan reached no "
              "shard, its scans there are mapped by none (outside_region per shard:%s)",
              v.vehicle.c_str(), v.silent ? " (silent since)" : "", v.per_shard.c_str());
        }
      });

  Refusals refusals;
  ros::WallTimer timer =
      nh.createWallTimer(ros::WallDuration(1.0 / rate), [&](const ros::WallTimerEvent&) {
        for (auto& kv : layers) {
          Scale& l = kv.second;
          if (!l.changed) continue;
          l.changed = false;
          std::vector<const nav_msgs::OccupancyGrid*> parts;
          for (const auto& m : l.latest) parts.push_back(m.get());
          nav_msgs::OccupancyGrid out;
          std::string why;
          const wavog_fleet::SiteRefusal r =
              wavog_fleet::assembleSiteLayer(parts, max_cells, &out, &why);
          if (r == wavog_fleet::SiteRefusal::kNone) {
            l.pub.publish(out);
            ++l.published;
            continue;
          }
          if (r == wavog_fleet::SiteRefusal::kBadLayer) ++refusals.bad_layer;
          if (r == wavog_fleet::SiteRefusal::kMismatch) ++refusals.mismatch;
          if (r == wavog_fleet::SiteRefusal::kTooLarge) ++refusals.too_large;
          if (r == wavog_fleet::SiteRefusal::kNothingKnown) {  // no vehicle in any region yet
            ROS_INFO_THROTTLE(30.0, "wavog_site: site_map_scale_%d not published yet: %s",
                              l.scale, why.c_str());
            continue;
          }
          refusals.last = "site_map_scale_" + std::to_string(l.scale) + ": " + why;
          ROS_WARN_THROTTLE(5.0, "wavog_site: site_map_scale_%d not published: %s", l.scale,
                            why.c_str());
        }
      });

  diagnostic_updater::Updater updater(nh, pnh, pnh.getNamespace());
  updater.setHardwareID("wavog_mapping");
  updater.add("site", [&](diagnostic_updater::DiagnosticStatusWrapper& s) {
    const std::uint64_t refused = refusals.bad_layer + refusals.mismatch + refusals.too_large;
    if (!silent.empty() && (ros::WallTime::now() - started).toSec() >= kSilentAfter) {
      s.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                "no publisher on " + std::to_string(silent.size()) + " topics: " + silent[0]);
    } else if (!overlaps.empty()) {
      s.summary(diagnostic_msgs::DiagnosticStatus::WARN, "regions overlap: " + overlaps[0]);
    } else if (refused > 0) {
      s.summary(diagnostic_msgs::DiagnosticStatus::WARN, "layers refused: " + refusals.last);
    } else if (!site.outside.empty()) {
      s.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                std::to_string(site.outside.size()) + " vehicle(s) outside every region");
    } else {
      s.summary(diagnostic_msgs::DiagnosticStatus::OK, "assembling");
    }
    for (const auto& kv : layers) {
      s.add("site_map_scale_" + std::to_string(kv.first) + " published", kv.second.published);
    }
    s.add("layers refused: bad layer", refusals.bad_layer);
    s.add("layers refused: shards disagree", refusals.mismatch);
    s.add("layers refused: over max_cells", refusals.too_large);
    s.add("every shard reported", site.complete);
    s.add("topics without a publisher", silent.size());
    s.add("vehicles outside every region", site.outside.size());
    std::string names;
    for (const auto& v : site.outside) {
      names += (names.empty() ? "" : " ") + v.vehicle + (v.silent ? " (silent)" : "");
    }
    s.add("outside every region", names);
    s.add("scans mapped by no shard (at most)", site.scans_mapped_by_none_max);
    std::uint64_t restarts = 0;
    for (std::size_t i = 0; i < shards.size(); ++i) restarts += lives.restarts(i);
    s.add("shard restarts", restarts);
    s.add("overlapping regions", overlaps.size());
  });
  ros::WallTimer diag_timer = nh.createWallTimer(
      ros::WallDuration(1.0), [&](const ros::WallTimerEvent&) { updater.update(); });

  ROS_INFO("wavog_site: assembling %zu scales of %zu shards (at most %llu cells a layer)",
           layers.size(), shards.size(), static_cast<unsigned long long>(max_cells));
  ros::spin();
  return 0;
}
