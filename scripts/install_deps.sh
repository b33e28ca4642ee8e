#!/usr/bin/env bash
# Installs what wavog_mapping needs from Debian 12's archive (with `fuzz`: what make fuzz needs
# too). Idempotent: when every package is already installed it returns in well under a second
# without touching the network.
set -euo pipefail

PKGS=(
  build-essential cmake pkg-config zlib1g-dev libeigen3-dev libgtest-dev libgmock-dev
  libbenchmark-dev libpng-dev liboctomap-dev
  ros-base-dev catkin libroscpp-dev libnodelet-dev pluginlib-dev
  libtf2-ros-dev liblaser-geometry-dev libdiagnostic-updater-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libsensor-msgs-dev libnav-msgs-dev libstd-srvs-dev libmap-msgs-dev libgeometry-msgs-dev
  libvisualization-msgs-dev
  librosbag-dev librosbag-storage-dev python3-rosbag python3-rostest python3-roslaunch
  python3-rosmaster python3-rostopic python3-rosnode python3-tf2-ros python3-rosgraph rosout
  python3-catkin-pkg python3-genmsg python3-gencpp python3-genpy libyaml-cpp-dev
  nlohmann-json3-dev libcli11-dev python3-matplotlib python3-pil
  ros-message-generation ros-message-runtime
  libcli11-dev nlohmann-json3-dev python3-matplotlib python3-numpy
  # What the README's commands use at run time: rosrun, rostopic / rosservice / dynparam on the
  # mapper's topics (Python message modules), the install-space test's map check.
  rosbash python3-rospy python3-rosservice python3-rosparam python3-nav-msgs python3-sensor-msgs
  python3-map-msgs python3-std-srvs python3-diagnostic-msgs python3-geometry-msgs python3-std-msgs
  python3-visualization-msgs
  # make lint: the package checked as released ROS packages are (catkin_lint -W1).
  catkin-lint
)
# `install_deps.sh fuzz` (make fuzz): clang and its libFuzzer / sanitizer runtimes as well.
if [ "${1:-}" = fuzz ]; then
  PKGS+=(clang-14 libclang-rt-14-dev)
fi

missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
  echo "install_deps: missing packages (${missing[*]}); run as root or install them" >&2
  exit 1
fi
echo "install_deps: installing ${#missing[@]} package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
