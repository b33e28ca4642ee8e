// dynamic_reconfigure <-> Config (see reconfigure.h). Each run-time parameter is named once, in
// kNumbers (or, for the scales, in the two functions below it), for both directions.
#include "reconfigure.h"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <stdexcept>

namespace wavog_ros {
namespace {

/// One number of cfg/Mapping.cfg and where it lives in Config; "scales", "policy", "init",
/// "map_values" and "scale_aggregation" (strings) are the other run-time parameters.
struct NumberField {
  double wavog_mapping::MappingConfig::*reconfigure;
  double& (*in)(Config&);
};

const NumberField kNumbers[] = {
    {&wavog_mapping::MappingConfig::gamma, [](Config& c) -> double& { return c.map.policy.gamma; }},
    {&wavog_mapping::MappingConfig::forget_half_life,
     [](Config& c) -> double& { return c.map.policy.forget_half_life; }},
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
    {&wavog_mapping::MappingConfig::occupied_thresh,
     [](Config& c) -> double& { return c.ros.grid_values.occupied_thresh; }},
    {&wavog_mapping::MappingConfig::free_thresh,
     [](Config& c) -> double& { return c.ros.grid_values.free_thresh; }},
};

}  // namespace

wavog_mapping::MappingConfig toReconfigure(const Config& config) {
  Config c = config;
  wavog_mapping::MappingConfig rc;
  for (const NumberField& f : kNumbers) rc.*f.reconfigure = f.in(c);
  rc.scales = joinScales(c.ros.publish_scales);
  rc.policy = wavog::toString(c.map.policy.type);
  rc.init = wavog::toString(c.map.policy.init);
  rc.map_values = c.ros.grid_values.trinary ? "trinary" : "graded";
  rc.scale_aggregation = toString(c.ros.scale_aggregation);
  return rc;
}

Config withReconfigure(const Config& config, const wavog_mapping::MappingConfig& rc,
                       std::vector<std::string>* errors) {
  Config next = config;
  for (const NumberField& f : kNumbers) f.in(next) = rc.*f.reconfigure;
  if (!parseScales(rc.scales, &next.ros.publish_scales)) {
    errors->push_back("scales ('" + rc.scales + "') must be comma-separated integers");
  }
  if (!wavog::fromString(rc.policy, &next.map.policy.type)) {
    errors->push_back("policy ('" + rc.policy +
                      "') must be one of: none, max, clamp, forget, clamp_lower, clamp_upper");
  }
  if (!wavog::fromString(rc.init, &next.map.policy.init)) {
    errors->push_back("init ('" + rc.init + "') must be one of: unknown, empty_bound");
  }
  if (rc.map_values == "trinary" || rc.map_values == "graded") {
    next.ros.grid_values.trinary = rc.map_values == "trinary";
  } else {
    errors->push_back("map_values ('" + rc.map_values + "') must be one of: trinary, graded");
  }
  if (!fromString(rc.scale_aggregation, &next.ros.scale_aggregation)) {
    errors->push_back("scale_aggregation ('" + rc.scale_aggregation +
                      "') must be one of: max, mean");
  }
  for (const auto& e : next.map.validate()) errors->push_back(e);
  // The reconfigure key of publish_scales is `scales`: a refusal names the key the user set.
  const std::string file_key = "publish_scales";
  for (std::string e : validate(next.ros, next.map)) {
    if (e.compare(0, file_key.size(), file_key) == 0) e = "scales" + e.substr(file_key.size());
    errors->push_back(e);
  }
  return next;
}

ReconfigureServer::ReconfigureServer(const ros::NodeHandle& pnh,
                                     const wavog_mapping::MappingConfig& initial, Apply apply)
    : pnh_(pnh), current_(initial), apply_(std::move(apply)) {
  descriptions_pub_ =
      pnh_.advertise<dynamic_reconfigure::ConfigDescription>("parameter_descriptions", 1, true);
  descriptions_pub_.publish(wavog_mapping::MappingConfig::__getDescriptionMessage__());
  updates_pub_ = pnh_.advertise<dynamic_reconfigure::Config>("parameter_updates", 1, true);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    publishLocked();
  }
  set_srv_ = pnh_.advertiseService("set_parameters", &ReconfigureServer::onSet, this);
}

bool ReconfigureServer::onSet(dynamic_reconfigure::Reconfigure::Request& req,
                              dynamic_reconfigure::Reconfigure::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  wavog_mapping::MappingConfig next = current_;  // parameters not in the request keep their value
  std::vector<std::string> errors;
  if (!next.__fromMessage__(req.config)) {
    errors.emplace_back("the request names a parameter that cfg/Mapping.cfg does not have");
  } else {
    errors = apply_(next);
  }
  if (errors.empty()) {
    current_ = next;
    publishLocked();
    current_.__toMessage__(res.config);
    return true;
  }
  // Refused: the values in force go out again (parameter_updates, the parameter server), so that
  // a client that showed the proposed value (rqt_reconfigure) shows the old one; the call fails
  // with the reasons, so that `dynparam set` exits non-zero instead of returning as if it had
  // worked.
  // roscpp logs the exception's text as an error ("Exception thrown while processing service
  // call: ...") and answers it to the caller.
  publishLocked();
  std::string text;
  for (const auto& e : errors) text += "\n  " + e;
  throw std::invalid_argument(pnh_.getNamespace() +
                              ": reconfiguration refused, keeping the previous values:" + text);
}

void ReconfigureServer::publishLocked() {
  current_.__toServer__(pnh_);
  dynamic_reconfigure::Config msg;
  current_.__toMessage__(msg);
  updates_pub_.publish(msg);
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
