// World files: a scenario as YAML or JSON (JSON is read as YAML flow style). Angles in degrees.
//   name: car_park
//   duration: 60                      # s
//   region: [xmin, ymin, xmax, ymax]  # ground truth and pictures (m)
//   objects:                          # kind: wall | car | pedestrian | obstacle
//                                     # role: static | moving | departing | arriving
//     - {name: w, kind: wall, polygon: [[x, y], ...]}      # no trajectory: world frame
//     - {name: c, kind: car, role: departing, box: [length, width],   # or polygon, circle
//        trajectory: [[t, x, y, yaw_deg], ...], appear: t0, disappear: t1}
//     - {name: p, kind: pedestrian, circle: [radius, sides],
//        route: {speed: 1, start: 2, corner_radius: 0, points: [[x, y], ...]}}
//   vehicle: {box: [8, 2.5], trajectory: [...] or route: {...}, lasers: [...]}
// A laser: {name, frame_id, topic, x, y, yaw_deg, beams, fov_deg, range_min, range_max, rate_hz,
// phase_s, noise_sigma, dropout_prob}, every key optional (LMS-291 defaults), or
// {corner: front_left | front_right | rear_left | rear_right, ...} for one at a corner of the
// vehicle's box facing outwards at 45 deg.
#ifndef WAVOG_MAPPING_SIM_WORLD_FILE_H_
#define WAVOG_MAPPING_SIM_WORLD_FILE_H_

#include <stdexcept>
#include <string>

#include "wavog_mapping/sim/world.h"

namespace wavog {
namespace sim {

/// A world file could not be read; what() names the file, the entry and the reason.
class WorldFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a world from YAML or JSON text; `origin` names the source in error messages.
/// Throws WorldFileError on a syntax error, an unknown key, a bad value or an invalid world.
World parseWorld(const std::string& text, const std::string& origin = "<string>");
/// Reads a world file (YAML or JSON). Throws WorldFileError.
World loadWorld(const std::string& path);
/// The world as YAML that parseWorld reads back to the same world (polygons and waypoints
/// explicit, angles in degrees printed with full precision).
std::string worldToYaml(const World& world);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SIM_WORLD_FILE_H_
