// dynamic_reconfigure <-> Config (see reconfigure.h). Each run-time parameter is named once, in
// kNumbers (or, for the scales, in the two functions below it), for both directions.
#include "reconfigure.h"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace wavog_ros {
namespace {

/// One number of cfg/Mapping.cfg and where it lives in Config; "scales" (a string) is the only
/// other run-time parameter.
struct NumberField {
  double wavog_mapping::MappingConfig::*reconfigure;
  double& (*in)(Config&);
};

const NumberField kNumbers[] = {
    {&wavog_mapping::MappingConfig::gamma, [](Config& c) -> double& { return c.map.policy.gamma; }},
    {&wavog_mapping::MappingConfig::clamp_min,
     [](Config& c) -> double& { return c.map.policy.clamp_min; }},
    {&wavog_mapping::MappingConfig::clamp_max,
     [](Config& c) -> double& { return c.map.policy.clamp_max; }},
    {&wavog_mapping::MappingConfig::odd_occ,
     [](Config& c) -> double& { return c.map.sensor.odd_occ; }},
    {&wavog_mapping::MappingConfig::odd_emp,
     [](Config& c) -> double& { return c.map.sensor.odd_emp; }},
    {&wavog_mapping::MappingConfig::publish_rate,
     [](Config& c) -> double& { return c.ros.publish_rate; }},
};

}  // namespace

wavog_mapping::MappingConfig toReconfigure(const Config& config) {
  Config c = config;
  wavog_mapping::MappingConfig rc;
  for (const NumberField& f : kNumbers) rc.*f.reconfigure = f.in(c);
  rc.scales = joinScales(c.ros.publish_scales);
  return rc;
}

Config withReconfigure(const Config& config, const wavog_mapping::MappingConfig& rc,
                       std::vector<std::string>* errors) {
  Config next = config;
  for (const NumberField& f : kNumbers) f.in(next) = rc.*f.reconfigure;
  if (!parseScales(rc.scales, &next.ros.publish_scales)) {
    errors->push_back("scales ('" + rc.scales + "') must be comma-separated integers");
  }
  for (const auto& e : next.map.validate()) errors->push_back(e);
  for (const auto& e : validate(next.ros, next.map)) errors->push_back(e);
  return next;
}

bool parseScales(const std::string& text, std::vector<int>* scales) {
  scales->clear();
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item.erase(std::remove_if(item.begin(), item.end(),
                              [](unsigned char c) { return std::isspace(c) != 0; }),
               item.end());
    if (item.empty()) continue;
    std::size_t used = 0;
    try {
      scales->push_back(std::stoi(item, &used));
    } catch (const std::exception&) {
      return false;
    }
    if (used != item.size()) return false;
  }
  return true;
}

std::string joinScales(const std::vector<int>& scales) {
  std::string out;
  for (int s : scales) out += (out.empty() ? "" : ",") + std::to_string(s);
  return out;
}

}  // namespace wavog_ros
