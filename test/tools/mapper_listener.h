// The latest ~status and /map of the mapper a real-bag rostest plays a bag through
// (test_real_bag.cpp, test_real_bags.cpp): subscribed on construction, read under a lock.
#ifndef WAVOG_MAPPING_TEST_TOOLS_MAPPER_LISTENER_H_
#define WAVOG_MAPPING_TEST_TOOLS_MAPPER_LISTENER_H_

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <mutex>

#include "wavog_mapping/MapperStatus.h"

namespace wavog_test {

class MapperListener {
 public:
  explicit MapperListener(ros::NodeHandle& nh)
      : status_sub_(nh.subscribe("/wavog_mapping/status", 10, &MapperListener::onStatus, this)),
        map_sub_(nh.subscribe("/map", 1, &MapperListener::onMap, this)) {}

  /// Sets *input to the first input's row of the latest status, if there is one.
  void firstInput(wavog_mapping::InputStatus* input) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (status_ && !status_->inputs.empty()) *input = status_->inputs[0];
  }
  /// Stops listening to the status (so that a new subscriber of it is a subscriber of its own).
  void stopStatus() { status_sub_.shutdown(); }
  nav_msgs::OccupancyGrid::ConstPtr map() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return map_;
  }

 private:
  void onStatus(const wavog_mapping::MapperStatus::ConstPtr& s) {
    std::lock_guard<std::mutex> lock(mutex_);
    status_ = s;
  }
  void onMap(const nav_msgs::OccupancyGrid::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    map_ = m;
  }

  mutable std::mutex mutex_;
  wavog_mapping::MapperStatus::ConstPtr status_;
  nav_msgs::OccupancyGrid::ConstPtr map_;
  ros::Subscriber status_sub_, map_sub_;
};

}  // namespace wavog_test

#endif  // WAVOG_MAPPING_TEST_TOOLS_MAPPER_LISTENER_H_
