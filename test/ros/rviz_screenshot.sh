#!/usr/bin/env bash
# make rviz-check: runs test/rviz_check.launch under Xvfb, grabs the screen after the map arrived,
# writes the screenshot to $1 and checks that the map is drawn: the free room renders near-white
# (rviz "map" colour scheme), which nothing else in the default view does.
set -euo pipefail
out=${1:?usage: rviz_screenshot.sh OUT.png}
mkdir -p "$(dirname "$out")"
display=:97
Xvfb $display -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
xvfb_pid=$!
export DISPLAY=$display LIBGL_ALWAYS_SOFTWARE=1
roslaunch wavog_mapping rviz_check.launch >"${out%.png}.log" 2>&1 &
launch_pid=$!
cleanup() { kill "$launch_pid" 2>/dev/null || true; wait "$launch_pid" 2>/dev/null || true;
            kill "$xvfb_pid" 2>/dev/null || true; }
trap cleanup EXIT
sleep "${RVIZ_WAIT:-25}"
import -display $display -window root "$out"
# Fraction of near-white pixels (free cells).
bright=$(convert "$out" -colorspace Gray -threshold 90% -format "%[fx:mean]" info:)
echo "rviz-check: screenshot $out, near-white fraction $bright"
awk -v b="$bright" 'BEGIN { exit !(b > 0.02) }' || { echo "rviz-check: the map is not drawn"; exit 1; }
echo "rviz-check: map drawn"
