// Publication of the map: the `map` layer (latched) with its `map_metadata` (latched) and the
// map_scale_<s> layers, cut to a window around the robot or the whole map, and over the same
// boxes with MapParams::reflection the `reflection` (latched) and reflection_scale_<s> layers,
// with MapParams::ndt the NDT cells as ndt_markers / ndt_cells (latched) and
// ndt_markers_scale_<s> / ndt_cells_scale_<s>; map_updates, the changed rectangle of the finest
// layer, from one dirty region. readOccupancy() reads one layer's occupancy as it is published
// (also for the dynamic_map service). Reads happen under the caller's lock
// (MappingRos::Impl::mutex_, which guards this object and the map); publish() and
// publishUpdate() run without it.
#ifndef WAVOG_MAPPING_SRC_ROS_MAP_PUBLISHER_H_
#define WAVOG_MAPPING_SRC_ROS_MAP_PUBLISHER_H_

#include <ros/node_handle.h>

#include <map>
#include <string>
#include <vector>

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/ros/config.h"
#include "wavog_mapping/ros/conversions.h"

namespace wavog_ros {

/// An axis-aligned box of the map frame (m).
struct MapBox {
  double min_x = 0.0, min_y = 0.0, max_x = 0.0, max_y = 0.0;
};

/// The part of the finest layer changed since the last map_updates message.
struct DirtyRegion {
  bool any = false;
  MapBox box;
  /// Grows the region to hold `b`.
  void add(const MapBox& b);
};

/// The layers of one full publication, read from the map.
struct Layers {
  struct Layer {
    int scale = 0;
    ros::Publisher pub;              ///< occupancy; null when only its payloads are wanted
    ros::Publisher metadata_pub;     ///< `map_metadata` (the finest layer only), else null
    ros::Publisher reflection_pub;   ///< null when its reflection is not wanted
    ros::Publisher ndt_markers_pub;  ///< null when its NDT markers are not wanted
    ros::Publisher ndt_cells_pub;    ///< null when its NDT cloud is not wanted
    wavog::Raster raster;
    wavog::ReflectionRaster reflection;  ///< over raster's box
    wavog::NdtLayer ndt;                 ///< over raster's box, when an NDT publisher is set
  };
  std::vector<Layer> layers;
  std::vector<std::string> refused;   ///< one line per layer larger than kMaxLayerCells
  std::vector<std::string> windowed;  ///< one line per whole layer published as a window instead
  wavog::GridValues values;           ///< of the occupancy grids (RosParams::grid_values)
};

/// Half-width, in cells of its scale, of the square a layer falls back to when the whole layer
/// would hold more than kMaxLayerCells: (2 x 2046 + 2)^2 cells, within 4096^2 = kMaxLayerCells.
constexpr double kFallbackWindowCells = 2046.0;

/// The occupancy raster of one layer as it is published: the cells of layerBox() (the window
/// around (cx, cy) when params.publish_window > 0, else the map's bounds) at `scale`, Haar mean at
/// scale 0 and params.scale_aggregation above, cut to the observed cells (an empty raster when
/// none is). A whole layer (publish_window 0) larger than kMaxLayerCells falls back to the square
/// of kFallbackWindowCells around (cx, cy): *windowed then says so ("scale s: W x H cells").
/// kTooLarge (a publish_window too large): *raster is empty and *refused says the layer's size.
/// Allocates no more than kMaxLayerCells cells. The map's lock is the caller's.
LayerSize readOccupancy(const wavog::WaveletMap& map, int scale, const RosParams& params, double cx,
                        double cy, wavog::Raster* raster, std::string* refused,
                        std::string* windowed);

class MapPublisher {
 public:
  /// Advertises map, map_metadata, map_updates and map_scale_<s> for `scales` on `nh`; with
  /// `reflection`, also reflection and reflection_scale_<s>; with `ndt`, also ndt_markers,
  /// ndt_cells, ndt_markers_scale_<s> and ndt_cells_scale_<s>.
  MapPublisher(const ros::NodeHandle& nh, const std::vector<int>& scales, bool reflection,
               bool ndt);

  /// Publishes map_scale_<s> for exactly `scales` (publishers of kept scales are kept).
  void advertiseScales(const std::vector<int>& scales);
  /// The scales published besides `map` (scale 0).
  std::vector<int> scales() const;

  /// The scan or the service changed the map inside `box`.
  void touched(const MapBox& box) { dirty_.add(box); }
  /// The next map_updates carries the whole last full grid (after a reset).
  void markAllDirty(double resolution);
  /// The sensor of the last integrated scan was at (x, y) (map frame, m): the centre of a layer's
  /// fallback window when base_frame has no pose.
  void sensorAt(double x, double y);
  /// Where sensorAt() last put the sensor; false before the first scan.
  bool lastSensor(double* x, double* y) const;

  /// Reads `map` and every layer with subscribers, within `window` (half-width w around cx, cy)
  /// when w > 0, else the whole map, cut to the box of the observed cells. A layer with no
  /// observed cell is left out before its first publication, and afterwards published over its
  /// last box with every cell unknown (after ~reset or ~clear_region). Caller's lock.
  Layers read(const wavog::WaveletMap& map, const RosParams& params, double cx, double cy);
  /// Publishes what read() returned; with `map`, its info on map_metadata. No lock needed, but
  /// read() and publish(), and readUpdate() and publishUpdate(), must not interleave: the caller
  /// serialises them (MappingRos::Impl::publish_mutex_), so that a map_updates message never
  /// refers to a `map` that has not been sent.
  static void publish(const Layers& layers, const std::string& frame, const ros::Time& stamp);

  bool updateWanted() const { return update_pub_.getNumSubscribers() > 0; }
  /// Reads the dirty region, clipped to the last full `map`, and clears it; false if there is
  /// nothing to send, or while the box of `map` has just changed (a new box goes out as a full
  /// `map` twice before updates of it do). Caller's lock.
  bool readUpdate(const wavog::WaveletMap& map, wavog::Raster* raster, wavog::CellBox* full);
  /// Publishes what readUpdate() returned with `values`. No lock needed (see publish()).
  void publishUpdate(const wavog::Raster& raster, const wavog::CellBox& full,
                     const wavog::GridValues& values, const std::string& frame,
                     const ros::Time& stamp) const;

 private:
  ros::NodeHandle nh_;
  ros::Publisher map_pub_, metadata_pub_, update_pub_;
  std::map<int, ros::Publisher> scale_pubs_;
  bool reflection_ = false;
  ros::Publisher reflection_pub_;
  std::map<int, ros::Publisher> reflection_scale_pubs_;
  bool ndt_ = false;
  ros::Publisher ndt_markers_pub_, ndt_cells_pub_;
  std::map<int, ros::Publisher> ndt_markers_scale_pubs_, ndt_cells_scale_pubs_;
  DirtyRegion dirty_;
  bool have_full_ = false;
  wavog::CellBox last_full_box_;  ///< scale-0 box of the last full `map`
  bool full_box_stable_ = false;  ///< the last two full `map`s had the same box
  /// Per scale, the box of the last occupancy grid sent (an emptied layer keeps it).
  std::map<int, wavog::CellBox> last_box_;
  bool have_sensor_ = false;
  double sensor_x_ = 0.0, sensor_y_ = 0.0;
};

}  // namespace wavog_ros

#endif  // WAVOG_MAPPING_SRC_ROS_MAP_PUBLISHER_H_
