#!/usr/bin/env bash
# Soak run of the node (make soak, mk/soak.mk): scripts/soak.sh BUILD OUT_DIR MINUTES RATE.
# Simulates MINUTES of the car park (wavog_simulate), starts a roscore of its own on a free port,
# the node (config/lms291_x4.yaml, use_sim_time) and the sampler (scripts/soak_sample.py), plays
# the bag at RATE x real time, then lets the sampler write the CSV, the PNG and the summary.
set -uo pipefail
build=${1:?usage: soak.sh BUILD OUT_DIR MINUTES RATE}
out=${2:?}
minutes=${3:?}
rate=${4:?}
root=$(cd "$(dirname "$0")/.." && pwd)
export PATH=/usr/bin:$PATH
set +u
# shellcheck disable=SC1091
source "$build/devel/setup.bash"
set -u
mkdir -p "$out"
export ROS_HOME=$out/ros_home ROS_LOG_DIR=$out/ros_home/log
bag=$out/soak_${minutes}min.bag
seconds=$((minutes * 60))
if [ ! -s "$bag" ]; then
  echo "soak: simulating $minutes min of the car park into $bag"
  "$build/devel/lib/wavog_mapping/wavog_simulate" --duration "$seconds" --out "$bag.tmp" >"$out/simulate.log" 2>&1 \
    || { cat "$out/simulate.log"; exit 1; }
  mv "$bag.tmp" "$bag"
fi

port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; wait 2>/dev/null; }
trap cleanup EXIT
roscore -p "$port" >"$out/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done
rosparam set /use_sim_time true
rosparam load "$root/config/lms291_x4.yaml" /wavog_mapping
"$build/devel/lib/wavog_mapping/wavog_mapping_node" __name:=wavog_mapping >"$out/node.log" 2>&1 &
node=$!
pids+=($node)
/usr/bin/python3 "$root/scripts/soak_sample.py" --pid "$node" --bag "$bag" --out "$out" \
  --rate "$rate" >"$out/sampler.log" 2>&1 &
sampler=$!
sleep 3
echo "soak: playing $bag at ${rate}x (node pid $node); figures in $out"
rosbag play --clock -q -r "$rate" "$bag" >"$out/play.log" 2>&1
touch "$out/played"
wait "$sampler"
status=$?
rm -f "$out/played"
cat "$out/soak.txt" 2>/dev/null || cat "$out/sampler.log"
kill -0 "$node" 2>/dev/null || { echo "soak: the node died (see $out/node.log)"; status=1; }
exit $status
