// wavog_site's parts without a roscore (issue 36): the shards' layers put together cell for cell,
// every malformed or hostile layer refused under its reason without writing outside the site grid
// or allocating past ~max_cells, and the vehicles outside every region from the shards' statuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "fleet/site_layers.h"
#include "fleet/site_params.h"
#include "fleet/site_vehicles.h"

namespace {

using wavog_fleet::assembleSiteLayer;
using wavog_fleet::kDefaultMaxSiteCells;
using wavog_fleet::SiteRefusal;

// A width x height layer at 0.8 m with its origin at cell (x0, y0), every cell `value`.
nav_msgs::OccupancyGrid layer(std::int64_t x0, std::int64_t y0, std::uint32_t width,
                              std::uint32_t height, std::int8_t value, double stamp = 10.0) {
  nav_msgs::OccupancyGrid g;
  g.header.frame_id = "map";
  g.header.stamp = ros::Time(stamp);
  g.info.resolution = 0.8f;
  g.info.width = width;
  g.info.height = height;
  g.info.origin.position.x = static_cast<double>(x0) * 0.8f;
  g.info.origin.position.y = static_cast<double>(y0) * 0.8f;
  g.info.origin.orientation.w = 1.0;
  g.data.assign(static_cast<std::size_t>(width) * height, value);
  return g;
}

SiteRefusal assemble(const std::vector<const nav_msgs::OccupancyGrid*>& parts,
                     nav_msgs::OccupancyGrid* out, std::uint64_t max_cells = kDefaultMaxSiteCells) {
  std::string why;
  const SiteRefusal r = assembleSiteLayer(parts, max_cells, out, &why);
  EXPECT_EQ(r == SiteRefusal::kNone, why.empty()) << why;
  if (r != SiteRefusal::kNone) {
    EXPECT_TRUE(out->data.empty()) << why;
    EXPECT_EQ(out->info.width, 0u) << why;
  }
  return r;
}

TEST(SiteLayers, PutsTheShardsKnownCellsOnOneGrid) {
  nav_msgs::OccupancyGrid a = layer(-4, 2, 3, 2, 0, 12.0);
  nav_msgs::OccupancyGrid b = layer(5, -1, 2, 2, 100, 11.0);
  a.data[1] = -1;  // unknown in a shard stays unknown
  nav_msgs::OccupancyGrid out;
  ASSERT_EQ(assemble({&a, nullptr, &b}, &out), SiteRefusal::kNone);
  EXPECT_EQ(out.info.width, 11u);  // cells -4 .. 6
  EXPECT_EQ(out.info.height, 5u);  // cells -1 .. 3
  EXPECT_DOUBLE_EQ(out.info.origin.position.x, -4 * 0.8f);
  EXPECT_DOUBLE_EQ(out.info.origin.position.y, -1 * 0.8f);
  EXPECT_EQ(out.header.stamp, ros::Time(11.0));  // the oldest part's
  EXPECT_EQ(out.header.frame_id, "map");
  int known_a = 0, known_b = 0;
  for (std::uint32_t y = 0; y < out.info.height; ++y) {
    for (std::uint32_t x = 0; x < out.info.width; ++x) {
      const int cx = static_cast<int>(x) - 4, cy = static_cast<int>(y) - 1;
      const std::int8_t v = out.data[y * out.info.width + x];
      const bool in_a = cx >= -4 && cx < -1 && cy >= 2 && cy < 4 && !(cx == -3 && cy == 2);
      const bool in_b = cx >= 5 && cx < 7 && cy >= -1 && cy < 1;
      EXPECT_EQ(v, in_a ? 0 : in_b ? 100 : -1) << cx << "," << cy;
      known_a += in_a;
      known_b += in_b;
    }
  }
  EXPECT_EQ(known_a, 5);
  EXPECT_EQ(known_b, 4);
}

TEST(SiteLayers, NothingKnownUntilAShardPublishes) {
  nav_msgs::OccupancyGrid empty = layer(0, 0, 0, 0, 0);
  nav_msgs::OccupancyGrid out;
  EXPECT_EQ(assemble({}, &out), SiteRefusal::kNothingKnown);
  EXPECT_EQ(assemble({nullptr, &empty}, &out), SiteRefusal::kNothingKnown);
}

TEST(SiteLayers, RefusesASiteOverMaxCellsBeforeAllocating) {
  // Two shards 2^33 cells apart: a grid of width 2^33 + 1 wraps a 32-bit width; before the check
  // this wrote outside the site grid.
  nav_msgs::OccupancyGrid a = layer(0, 0, 1, 1, 50);
  nav_msgs::OccupancyGrid b = layer(std::int64_t{1} << 33, 0, 1, 1, 50);
  nav_msgs::OccupancyGrid out;
  EXPECT_EQ(assemble({&a, &b}, &out), SiteRefusal::kTooLarge);
  nav_msgs::OccupancyGrid c = layer(0, std::int64_t{1} << 20, 1, 1, 50);
  nav_msgs::OccupancyGrid d = layer(std::int64_t{1} << 20, 0, 1, 1, 50);
  EXPECT_EQ(assemble({&a, &c, &d}, &out), SiteRefusal::kTooLarge);
  // The limit itself: a 100 x 10 site fits 1,000 cells, not 999.
  nav_msgs::OccupancyGrid e = layer(99, 9, 1, 1, 50);
  EXPECT_EQ(assemble({&a, &e}, &out, 1000), SiteRefusal::kNone);
  EXPECT_EQ(out.data.size(), 1000u);
  EXPECT_EQ(assemble({&a, &e}, &out, 999), SiteRefusal::kTooLarge);
}

TEST(SiteLayers, RefusesMalformedLayers) {
  nav_msgs::OccupancyGrid good = layer(0, 0, 2, 2, 0);
  nav_msgs::OccupancyGrid out;
  // Refused beside a good layer and alone (a layer in another frame is fine alone).
  auto bad = [&](const nav_msgs::OccupancyGrid& g, SiteRefusal expected, const char* what,
                 SiteRefusal alone) {
    EXPECT_EQ(assemble({&good, &g}, &out), expected) << what;
    EXPECT_EQ(assemble({&g}, &out), alone) << what << " alone";
  };
  nav_msgs::OccupancyGrid g = layer(3, 0, 2, 2, 0);
  g.data.pop_back();
  bad(g, SiteRefusal::kBadLayer, "data shorter than width x height", SiteRefusal::kBadLayer);
  g = layer(3, 0, 2, 2, 0);
  g.info.width = 0xffffffffu;
  bad(g, SiteRefusal::kBadLayer, "width far beyond the data", SiteRefusal::kBadLayer);
  for (float res : {0.0f, -0.8f, std::numeric_limits<float>::quiet_NaN(),
                    std::numeric_limits<float>::infinity()}) {
    g = layer(3, 0, 2, 2, 0);
    g.info.resolution = res;
    bad(g, SiteRefusal::kBadLayer, "resolution not a positive number", SiteRefusal::kBadLayer);
  }
  g = layer(3, 0, 2, 2, 0);
  g.info.origin.orientation.z = std::sin(0.25);
  g.info.origin.orientation.w = std::cos(0.25);
  bad(g, SiteRefusal::kBadLayer, "rotated", SiteRefusal::kBadLayer);
  for (std::int8_t v : {std::int8_t{101}, std::int8_t{-2}, std::int8_t{-128}, std::int8_t{127}}) {
    g = layer(3, 0, 2, 2, 0);
    g.data[3] = v;
    bad(g, SiteRefusal::kBadLayer, "a value outside -1 and 0..100", SiteRefusal::kBadLayer);
  }
  for (double x : {0.4 * 0.8, std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity(), 1e300, 0.8 * 2e12}) {
    g = layer(3, 0, 2, 2, 0);
    g.info.origin.position.x = x;
    bad(g, SiteRefusal::kMismatch, "origin off the lattice or beyond 2^40 cells",
        SiteRefusal::kMismatch);
  }
  g = layer(3, 0, 2, 2, 0);
  g.header.frame_id = "odom";
  bad(g, SiteRefusal::kMismatch, "another frame", SiteRefusal::kNone);
  g = layer(3, 0, 2, 2, 0);
  g.info.resolution = 0.4f;
  g.info.origin.position.x = 3 * 0.4f;
  EXPECT_EQ(assemble({&good, &g}, &out), SiteRefusal::kMismatch) << "another resolution";
}

// Statuses of shards, each listing vehicles: `outside` of the vehicle's scans (at least 10, all
// received and integrated) reached no block of the shard's region.
wavog_mapping::VehicleStatus vehicle(const std::string& name, bool in_region, std::uint64_t outside,
                                     bool stale = false) {
  wavog_mapping::VehicleStatus v;
  v.vehicle = name;
  v.received = v.integrated = std::max<std::uint64_t>(10, outside);
  v.in_region = in_region;
  v.outside_region = outside;
  v.stale = stale;
  return v;
}

// A vehicle's counters in one shard: `received` scans, `mapped` of them reached its region.
wavog_mapping::VehicleStatus counted(const std::string& name, std::uint64_t received,
                                     std::uint64_t mapped, bool in_region = false) {
  wavog_mapping::VehicleStatus v;
  v.vehicle = name;
  v.received = v.integrated = received;
  v.outside_region = received - mapped;
  v.in_region = in_region;
  return v;
}

wavog_mapping::FleetStatus::ConstPtr status(std::vector<wavog_mapping::VehicleStatus> vehicles) {
  wavog_mapping::FleetStatus::Ptr s(new wavog_mapping::FleetStatus);
  s->vehicles = std::move(vehicles);
  return s;
}

TEST(SiteVehicles, NamesVehiclesOutsideEveryRegionAndBoundsTheirScans) {
  const std::vector<std::string> shards = {"/a", "/b"};
  std::vector<wavog_mapping::FleetStatus::ConstPtr> st(2);
  st[0] = status({vehicle("v1", true, 3), vehicle("v2", false, 40), vehicle("v3", false, 7)});
  wavog_fleet::SiteVehicles site = wavog_fleet::summariseVehicles(st, shards);
  EXPECT_FALSE(site.complete);  // /b not heard from
  EXPECT_TRUE(site.outside.empty());

  st[1] = status({vehicle("v1", false, 5), vehicle("v2", false, 38),
                  vehicle("v3", false, 9, /*stale=*/true), vehicle("v4", false, 100)});
  site = wavog_fleet::summariseVehicles(st, shards);
  ASSERT_TRUE(site.complete);
  ASSERT_EQ(site.outside.size(), 1u);  // v1 reached /a; v3 stale in /b; v4 unknown to /a
  EXPECT_EQ(site.outside[0].vehicle, "v2");
  EXPECT_EQ(site.outside[0].per_shard, " /a: 40 /b: 38");
  // Per vehicle, the most scans a shard saw less the most a shard mapped: v1 10 - 7, v2 40 - 0
  // (/b saw 38 of them), v3 10 - 3.
  EXPECT_EQ(site.scans_mapped_by_none_max, 3u + 40u + 7u);

  st[0] = status({vehicle("v1", false, std::numeric_limits<std::uint64_t>::max()),
                  vehicle("v2", false, std::numeric_limits<std::uint64_t>::max())});
  st[1] = status({vehicle("v1", false, std::numeric_limits<std::uint64_t>::max()),
                  vehicle("v2", false, std::numeric_limits<std::uint64_t>::max())});
  site = wavog_fleet::summariseVehicles(st, shards);
  EXPECT_EQ(site.scans_mapped_by_none_max, std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(site.outside.size(), 2u);
}

// Issue 42: a shard restarts (its counters start again at 0). The scans mapped by none stay an
// upper bound: the restarted shard's earlier life is kept, and the scans sent while it was down
// are not mapped by it. Before, the bound was the smallest outside_region of the latest statuses:
// here 10 (the restarted shard's new count) where 100 scans reached no shard.
TEST(SiteVehicles, ScansMappedByNoneStayAnUpperBoundAcrossAShardRestart) {
  const std::vector<std::string> shards = {"/a", "/b"};
  std::vector<wavog_mapping::FleetStatus::ConstPtr> st(2);
  wavog_fleet::ShardLives lives(2);
  auto report = [&](std::size_t i, std::vector<wavog_mapping::VehicleStatus> v) {
    st[i] = status(std::move(v));
    lives.add(i, *st[i]);
  };
  // v1 outside every region: 50 scans, counted by both shards; v2 in /a's region.
  report(0, {counted("v1", 50, 0), counted("v2", 50, 50, true)});
  report(1, {counted("v1", 50, 0), counted("v2", 50, 0)});
  EXPECT_EQ(wavog_fleet::summariseVehicles(st, shards, lives).scans_mapped_by_none_max, 50u);
  // /a goes down; 20 more scans of each vehicle, /b alone receives them: v2's 20 are in /a's
  // region, mapped by none.
  report(1, {counted("v1", 70, 0), counted("v2", 70, 0)});
  // /a restarts and receives 10 more of each.
  report(0, {counted("v1", 10, 0), counted("v2", 10, 10, true)});
  report(1, {counted("v1", 80, 0), counted("v2", 80, 0)});
  const wavog_fleet::SiteVehicles site = wavog_fleet::summariseVehicles(st, shards, lives);
  EXPECT_EQ(lives.restarts(0), 1u);
  EXPECT_EQ(lives.restarts(1), 0u);
  EXPECT_EQ(lives.get(0, "v2").mapped, 60u);
  EXPECT_EQ(lives.get(0, "v2").seen, 60u);
  // 80 of v1 and 20 of v2 reached no shard; the bound holds them all, exactly here.
  EXPECT_EQ(site.scans_mapped_by_none_max, 80u + 20u);
  ASSERT_EQ(site.outside.size(), 1u);
  EXPECT_EQ(site.outside[0].vehicle, "v1");
  // A second restart of /a keeps both earlier lives.
  report(0, {counted("v1", 5, 0), counted("v2", 5, 5, true)});
  EXPECT_EQ(lives.restarts(0), 2u);
  EXPECT_EQ(lives.get(0, "v2").mapped, 65u);
  EXPECT_EQ(wavog_fleet::summariseVehicles(st, shards, lives).scans_mapped_by_none_max,
            80u + 80u - 65u);
}

// Scans a shard lost or refused are not mapped by it (a scan in its region it lost is mapped by
// none).
TEST(SiteVehicles, ScansAShardLostOrRefusedAreNotMappedByIt) {
  const std::vector<std::string> shards = {"/a", "/b"};
  std::vector<wavog_mapping::FleetStatus::ConstPtr> st(2);
  wavog_mapping::VehicleStatus a = counted("v", 40, 40, true);
  a.lost = 6;       // 6 scans in /a's region never delivered to /a
  a.received = 44;  // 4 of them refused
  a.dropped_bad_pose = 4;
  st[0] = status({a});
  st[1] = status({counted("v", 50, 0)});
  EXPECT_EQ(wavog_fleet::summariseVehicles(st, shards).scans_mapped_by_none_max, 10u);
}

// Issue 42: a vehicle outside every region stays listed once it goes silent (stale in every
// shard, its last scan the same in each); before, it dropped out of /diagnostics.
TEST(SiteVehicles, AVehicleOutsideEveryRegionStaysListedOnceSilent) {
  const std::vector<std::string> shards = {"/a", "/b"};
  std::vector<wavog_mapping::FleetStatus::ConstPtr> st(2);
  wavog_mapping::VehicleStatus a = vehicle("v", false, 20, /*stale=*/true);
  wavog_mapping::VehicleStatus b = vehicle("v", false, 20, /*stale=*/true);
  a.last_stamp = b.last_stamp = ros::Time(30.0);
  st[0] = status({a});
  st[1] = status({b});
  wavog_fleet::SiteVehicles site = wavog_fleet::summariseVehicles(st, shards);
  ASSERT_EQ(site.outside.size(), 1u);
  EXPECT_EQ(site.outside[0].vehicle, "v");
  EXPECT_TRUE(site.outside[0].silent);
  // Its last scan reached /b: not outside.
  b.in_region = true;
  st[1] = status({b});
  EXPECT_TRUE(wavog_fleet::summariseVehicles(st, shards).outside.empty());
  // The shards' last scans differ (/b has not got the latest one): not known, not named.
  b.in_region = false;
  b.last_stamp = ros::Time(29.0);
  st[1] = status({b});
  EXPECT_TRUE(wavog_fleet::summariseVehicles(st, shards).outside.empty());
  // Fresh in every shard: named, not silent.
  a.stale = b.stale = false;
  st[0] = status({a});
  st[1] = status({b});
  site = wavog_fleet::summariseVehicles(st, shards);
  ASSERT_EQ(site.outside.size(), 1u);
  EXPECT_FALSE(site.outside[0].silent);
}

// Issue 42: wavog_site's parameters; each bad value refused naming the parameter and its range.
XmlRpc::XmlRpcValue siteParams(const std::string& key, const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue root;
  root["shards"][0] = std::string("shard_a");
  root["shards"][1] = std::string("shard_b");
  root["scales"][0] = 3;
  if (!key.empty()) root[key] = value;
  return root;
}

std::string refusal(const XmlRpc::XmlRpcValue& root) {
  try {
    wavog_fleet::readSiteParams(root);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(SiteParams, RefusesEveryBadValueNamingTheParameter) {
  const wavog_fleet::SiteParams p = wavog_fleet::readSiteParams(siteParams("", {}));
  EXPECT_EQ(p.shards, (std::vector<std::string>{"shard_a", "shard_b"}));
  EXPECT_EQ(p.scales, std::vector<int>{3});
  EXPECT_EQ(p.rate, 1.0);
  EXPECT_EQ(p.max_cells, kDefaultMaxSiteCells);
  EXPECT_EQ(wavog_fleet::readSiteParams(siteParams("rate", 2.5)).rate, 2.5);
  EXPECT_EQ(wavog_fleet::readSiteParams(siteParams("rate", 3)).rate, 3.0);
  EXPECT_EQ(wavog_fleet::readSiteParams(siteParams("max_cells", 1000)).max_cells, 1000u);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // roslaunch hands `rate:=nan` over as the string "nan"; a YAML .nan is a double NaN.
  for (const XmlRpc::XmlRpcValue& bad :
       {XmlRpc::XmlRpcValue(std::string("nan")), XmlRpc::XmlRpcValue(std::string("inf")),
        XmlRpc::XmlRpcValue(nan), XmlRpc::XmlRpcValue(inf), XmlRpc::XmlRpcValue(0.0),
        XmlRpc::XmlRpcValue(101.0), XmlRpc::XmlRpcValue(true)}) {
    const std::string why = refusal(siteParams("rate", bad));
    EXPECT_NE(why.find("~rate must be a number in (0, 100] Hz"), std::string::npos) << why;
  }
  for (const XmlRpc::XmlRpcValue& bad :
       {XmlRpc::XmlRpcValue(std::string("nan")), XmlRpc::XmlRpcValue(nan), XmlRpc::XmlRpcValue(inf),
        XmlRpc::XmlRpcValue(0), XmlRpc::XmlRpcValue(2.5),
        XmlRpc::XmlRpcValue(std::ldexp(1.0, 28) + 1.0)}) {
    const std::string why = refusal(siteParams("max_cells", bad));
    EXPECT_NE(why.find("~max_cells must be a"), std::string::npos) << why;
  }
  // scales:=[3.5] was read as 3.
  XmlRpc::XmlRpcValue whole = siteParams("", {});
  whole["scales"][1] = 4.0;
  EXPECT_EQ(wavog_fleet::readSiteParams(whole).scales, (std::vector<int>{3, 4}));
  for (const XmlRpc::XmlRpcValue& bad :
       {XmlRpc::XmlRpcValue(3.5), XmlRpc::XmlRpcValue(0), XmlRpc::XmlRpcValue(13),
        XmlRpc::XmlRpcValue(std::string("3"))}) {
    XmlRpc::XmlRpcValue root = siteParams("", {});
    root["scales"][1] = bad;
    const std::string why = refusal(root);
    EXPECT_NE(why.find("~scales must list the scales to assemble (each a whole number in [1, 12]"),
              std::string::npos)
        << why;
  }
  // [3, 3] was taken: the same layer assembled and published twice.
  XmlRpc::XmlRpcValue twice = siteParams("", {});
  twice["scales"][1] = 3;
  EXPECT_NE(refusal(twice).find("~scales must list the scales to assemble (each a whole number in "
                                "[1, 12], published by every shard in publish_scales): entry 3 is "
                                "listed twice"),
            std::string::npos)
      << refusal(twice);
  XmlRpc::XmlRpcValue same_shard = siteParams("", {});
  same_shard["shards"][1] = std::string("shard_a");
  EXPECT_NE(refusal(same_shard).find("is listed twice: list each shard once"), std::string::npos)
      << refusal(same_shard);
  XmlRpc::XmlRpcValue no_shards = siteParams("", {});
  no_shards["shards"] = XmlRpc::XmlRpcValue();
  EXPECT_NE(refusal(no_shards).find("~shards must list"), std::string::npos);
  XmlRpc::XmlRpcValue bad_shard = siteParams("", {});
  bad_shard["shards"][1] = std::string("9 bad");
  EXPECT_NE(refusal(bad_shard).find("~shards entry '9 bad' is not a ROS namespace"),
            std::string::npos);
}

TEST(SiteParams, NamesOverlappingRegions) {
  using wavog_fleet::ShardRegion;
  const std::vector<ShardRegion> apart = {{"/a", {-64, -64, 38.4, 102.4}},
                                          {"/b", {38.4, -64, 140.8, 102.4}}};
  EXPECT_TRUE(wavog_fleet::overlappingRegions(apart).empty());  // they share an edge only
  const std::vector<ShardRegion> overlap = {{"/a", {-64, -64, 44.8, 102.4}},
                                            {"/b", {38.4, -64, 140.8, 102.4}},
                                            {"/c", {200, 0, 300, 100}}};
  const std::vector<std::string> o = wavog_fleet::overlappingRegions(overlap);
  ASSERT_EQ(o.size(), 1u);
  EXPECT_EQ(o[0], "/a [-64, -64, 44.8, 102.4] and /b [38.4, -64, 140.8, 102.4]");
  const std::vector<ShardRegion> everything = {{"/a", {}}, {"/b", {38.4, -64, 140.8, 102.4}}};
  ASSERT_EQ(wavog_fleet::overlappingRegions(everything).size(), 1u);
  // fleet_region values as the parameter server holds them.
  XmlRpc::XmlRpcValue v;
  v[0] = 0;
  v[1] = -6.4;
  v[2] = 64;
  v[3] = 6.4;
  std::vector<double> r;
  ASSERT_TRUE(wavog_fleet::readRegion(v, &r));
  EXPECT_EQ(r, (std::vector<double>{0, -6.4, 64, 6.4}));
  v[3] = std::string("x");
  EXPECT_FALSE(wavog_fleet::readRegion(v, &r));
}

}  // namespace
