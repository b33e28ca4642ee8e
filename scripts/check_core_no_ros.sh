#!/usr/bin/env bash
# Fails if any file of the ROS-free core includes a ROS header.
set -euo pipefail
cd "$(dirname "$0")/.."
hits=$(grep -rnE '#include *[<"](ros/|tf2|tf2_ros/|nodelet/|pluginlib/|rosbag/|[a-z_]+_msgs/|[a-z_]+_srvs/)' \
  include/wavog_mapping/core src/core || true)
if [ -n "$hits" ]; then
  echo "ROS includes in the ROS-free core:"; echo "$hits"; exit 1
fi
echo "core is ROS-free"
