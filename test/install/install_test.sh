#!/usr/bin/env bash
# The install space works on its own: every file a user runs is there, and after
# `source <prefix>/setup.bash` (in an environment without the build tree or the sources)
# mapping.launch, mapping_node.launch and mapping_node.launch fixed_frame_laser:=true start and
# publish a /map with occupied and free cells from a short simulated bag.
#   install_test.sh --build BUILD_DIR   cmake --install BUILD_DIR with DESTDIR a temporary
#                                       directory, test that (ctest entry install_space); DESTDIR
#                                       because catkin installs its setup files by absolute path
#   install_test.sh --prefix PREFIX     test an existing install space (make install-check)
set -euo pipefail
set -m   # background jobs in their own process groups: SIGINT reaches roslaunch and roscore
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/wavog_install_test.XXXXXX")
keep=${WAVOG_KEEP_INSTALL_TEST:-0}
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -INT -- "-$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  [ "$keep" = 1 ] && echo "install_test: kept $work" || rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "install_test: FAIL: $*" >&2; exit 1; }

case "${1:-}" in
  --build)
    build=$(cd "${2:?build dir}" && pwd)
    configured=$(sed -n 's/^CMAKE_INSTALL_PREFIX:PATH=//p' "$build/CMakeCache.txt")
    [ -n "$configured" ] || fail "no CMAKE_INSTALL_PREFIX in $build/CMakeCache.txt"
    prefix=$work/dest$configured
    DESTDIR=$work/dest cmake --install "$build" >"$work/install.log" 2>&1 ||
      { cat "$work/install.log"; fail "cmake --install failed"; }
    if grep -E '^-- (Installing|Up-to-date): ' "$work/install.log" | grep -vq -- "-- [A-Za-z-]*: $work/dest/"; then
      cat "$work/install.log"; fail "cmake --install wrote outside DESTDIR"
    fi ;;
  --prefix) prefix=$(cd "${2:?prefix}" && pwd) ;;
  *) echo "usage: install_test.sh --build BUILD_DIR | --prefix PREFIX" >&2; exit 2 ;;
esac
echo "install_test: install space $prefix"

# ---- Files ----------------------------------------------------------------------------------
pkg=$prefix/share/wavog_mapping
bin=$prefix/lib/wavog_mapping
for f in setup.bash \
    lib/libwavog_mapping_nodelet.so lib/libwavog_core.so \
    lib/wavog_mapping/wavog_mapping_node lib/wavog_mapping/wavog_static_tf \
    lib/wavog_mapping/wavog_offline lib/wavog_mapping/wavog_log2bag \
    lib/wavog_mapping/wavog_simulate lib/wavog_mapping/wavog_evaluate \
    lib/wavog_mapping/wavog_rviz \
    include/wavog_mapping/core/wavelet_map.h include/wavog_mapping/core/params.h \
    include/wavog_mapping/MapperStatus.h include/wavog_mapping/InputStatus.h \
    include/wavog_mapping/SaveMap.h include/wavog_mapping/ClearRegion.h \
    include/wavog_mapping/MappingConfig.h \
    share/wavog_mapping/package.xml share/wavog_mapping/nodelet_plugins.xml \
    share/wavog_mapping/launch/mapping.launch share/wavog_mapping/launch/mapping_node.launch \
    share/wavog_mapping/launch/playback.launch share/wavog_mapping/config/default.yaml \
    share/wavog_mapping/config/lms291_x4.yaml share/wavog_mapping/rviz/wavog.rviz \
    share/wavog_mapping/msg/MapperStatus.msg share/wavog_mapping/srv/SaveMap.srv \
    share/wavog_mapping/cmake/wavog_mappingConfig.cmake; do
  [ -e "$prefix/$f" ] || fail "missing $f"
done
ls -d "$prefix"/lib/python3*/dist-packages/wavog_mapping/msg >/dev/null 2>&1 ||
  fail "missing the Python messages"
ls -d "$prefix"/lib/python3*/dist-packages/wavog_mapping/cfg >/dev/null 2>&1 ||
  fail "missing the Python dynamic_reconfigure module"
echo "install_test: files present"

# ---- The core API from the installed headers and library -------------------------------------
cat >"$work/core_user.cpp" <<'EOF'
#include <cstdio>
#include "wavog_mapping/core/wavelet_map.h"
int main() {
  wavog::MapParams p = wavog::MapParams::defaultsFor(wavog::PolicyType::kForget);
  wavog::WaveletMap map(p);
  std::printf("blocks %zu\n", static_cast<size_t>(map.stats(false).blocks));
  return 0;
}
EOF
g++ -std=c++17 -I"$prefix/include" -I/usr/include/eigen3 "$work/core_user.cpp" \
  -L"$prefix/lib" -lwavog_core -o "$work/core_user" 2>"$work/core_user.log" ||
  { cat "$work/core_user.log"; fail "a program using the installed core headers does not build"; }
LD_LIBRARY_PATH=$prefix/lib "$work/core_user" >/dev/null || fail "the core program does not run"
echo "install_test: core API builds and runs against the install space"

# ---- ROS: a clean environment with only the install space ------------------------------------
port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
ros_env() {
  env -i HOME="$work" PATH=/usr/bin:/bin ROS_HOME="$work/ros_home" ROS_LOG_DIR="$work/ros_home/log" \
    ROS_MASTER_URI="http://localhost:$port" ROS_HOSTNAME=localhost \
    bash -c "set +u; source '$prefix/setup.bash'; set -u; $1"
}
found=$(ros_env "rospack find wavog_mapping")
[ "$found" = "$pkg" ] || fail "rospack find wavog_mapping gives '$found', not $pkg"
ros_env "rospack plugins --attrib=plugin nodelet" | grep -q "$pkg/nodelet_plugins.xml" ||
  fail "the nodelet plugin is not registered from $pkg"

# A key the config file sets is not overridden by a launch default; an argument given overrides it.
printf 'map_frame: odom\ninputs: [scan]\n' >"$work/odom.yaml"
for launch in mapping.launch mapping_node.launch playback.launch; do
  dumped=$(ros_env "roslaunch --dump-params wavog_mapping $launch config:=$work/odom.yaml bag:=/none")
  echo "$dumped" | grep -q "^/wavog_mapping/map_frame: odom$" ||
    { echo "$dumped"; fail "$launch overrides the config's map_frame"; }
  dumped=$(ros_env "roslaunch --dump-params wavog_mapping $launch config:=$work/odom.yaml bag:=/none map_frame:=world")
  echo "$dumped" | grep -q "^/wavog_mapping/map_frame: world$" ||
    { echo "$dumped"; fail "$launch: map_frame:=world not applied"; }
done
echo "install_test: map_frame: the config's value holds unless given as an argument"

# The nodelet and the node start with the same configuration by default (issue 41).
nodelet_params=$(ros_env "roslaunch --dump-params wavog_mapping mapping.launch" | sort)
node_params=$(ros_env "roslaunch --dump-params wavog_mapping mapping_node.launch" | sort)
[ "$nodelet_params" = "$node_params" ] ||
  { diff <(echo "$nodelet_params") <(echo "$node_params") || true
    fail "mapping.launch and mapping_node.launch default to different configurations"; }
echo "install_test: mapping.launch and mapping_node.launch: the same default configuration"

# rviz:=true: rviz's fixed frame is the map frame, the config's or map_frame:= (issue 41), as the
# launch starts it (its command line, run with a stand-in rviz that prints its arguments).
mkdir -p "$work/fake_rviz"
printf '#!/bin/sh\necho "rviz $*"\n' >"$work/fake_rviz/rviz"
chmod +x "$work/fake_rviz/rviz"
for launch in mapping.launch mapping_node.launch playback.launch; do
  for case in "odom:" "world:map_frame:=world"; do
    want=${case%%:*} given=${case#*:}
    cmd=$(ros_env "roslaunch --args /rviz wavog_mapping $launch rviz:=true config:=$work/odom.yaml bag:=/none $given")
    got=$(ros_env "PATH='$work/fake_rviz':\$PATH; $cmd")
    echo "$got" | grep -Eq -- "-f $want( |\$)" ||
      fail "$launch $given: rviz does not get the fixed frame $want: $cmd -> $got"
  done
done
echo "install_test: rviz:=true: rviz's fixed frame is the map frame"

ros_env "rosrun wavog_mapping wavog_simulate --duration 4 --out '$work/scenario.bag'" >"$work/simulate.log" 2>&1 ||
  { cat "$work/simulate.log"; fail "wavog_simulate"; }

ros_env "exec roscore -p $port" >"$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do ros_env "rosparam list" >/dev/null 2>&1 && break; sleep 0.2; done
ros_env "rosparam list" >/dev/null 2>&1 || { cat "$work/roscore.log"; fail "roscore did not start"; }

# run_case NAME LAUNCH_ARGS PLAY_ARGS: roslaunch, play the bag, wait for a map, stop.
run_case() {
  local name=$1 launch=$2 play=$3 log=$work/$1.log
  ros_env "rosparam set /wavog_mapping/stale_from_last_run 1"
  ros_env "exec roslaunch wavog_mapping $launch" >"$log" 2>&1 &
  local launch_pid=$!
  pids+=($launch_pid)
  sleep 3
  ros_env "rosbag play --clock --quiet '$work/scenario.bag' $play" >>"$log.play" 2>&1 ||
    { cat "$log" "$log.play"; fail "$name: rosbag play"; }
  if ! ros_env "/usr/bin/python3 '$here/wait_for_map.py' /map 30" >"$log.wait" 2>&1; then
    cat "$log" "$log.wait"; fail "$name: no /map with occupied and free cells"
  fi
  kill -0 "$launch_pid" 2>/dev/null || { cat "$log"; fail "$name: roslaunch ended early"; }
  if ros_env "rosparam get /wavog_mapping/stale_from_last_run" >/dev/null 2>&1; then
    fail "$name: an old private parameter of the mapper survived the start (clear_params)"
  fi
  kill -INT -- "-$launch_pid"; wait "$launch_pid" 2>/dev/null || true
  grep -h 'wait_for_map' "$log.wait"
  echo "install_test: $name: ok"
}
run_case mapping "mapping.launch use_sim_time:=true" "scan_front_left:=scan"
run_case mapping_node "mapping_node.launch use_sim_time:=true" "scan_front_left:=scan"
# No tf in the bag at all: the laser held fixed to the map frame by wavog_static_tf.
run_case fixed_frame_laser \
  "mapping_node.launch use_sim_time:=true fixed_frame_laser:=true laser_frame:=laser_front_left" \
  "--topics /scan_front_left scan_front_left:=scan"
echo "install_test: passed"
