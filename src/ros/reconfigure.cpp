// dynamic_reconfigure <-> Config (see reconfigure.h). Each run-time parameter is named once per
// direction, here and nowhere else.
#include "reconfigure.h"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace wavog_ros {

wavog_mapping::MappingConfig toReconfigure(const Config& config) {
  wavog_mapping::MappingConfig rc;
  rc.gamma = config.map.policy.gamma;
  rc.clamp_min = config.map.policy.clamp_min;
  rc.clamp_max = config.map.policy.clamp_max;
  rc.odd_occ = config.map.sensor.odd_occ;
  rc.odd_emp = config.map.sensor.odd_emp;
  rc.publish_rate = config.ros.publish_rate;
  rc.scales = joinScales(config.ros.publish_scales);
  return rc;
}

Config withReconfigure(const Config& config, const wavog_mapping::MappingConfig& rc,
                       std::vector<std::string>* errors) {
  Config next = config;
  next.map.policy.gamma = rc.gamma;
  next.map.policy.clamp_min = rc.clamp_min;
  next.map.policy.clamp_max = rc.clamp_max;
  next.map.sensor.odd_occ = rc.odd_occ;
  next.map.sensor.odd_emp = rc.odd_emp;
  next.ros.publish_rate = rc.publish_rate;
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
