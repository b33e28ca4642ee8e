#!/usr/bin/env bash
# make rviz-check: simulates 40 s of the demo's car park, plays it through test/rviz_check.launch
# (playback.launch, config/lms291_x4.yaml, rviz/wavog.rviz) under Xvfb, grabs the screen,
# writes the screenshot to $1 and checks that the map is drawn: in rviz's "map" colour scheme
# unknown cells are grey-green (112, 137, 134) and free cells white; the view must show both.
set -euo pipefail
out=${1:?usage: rviz_screenshot.sh OUT.png}
mkdir -p "$(dirname "$out")"
display=:97
export WAVOG_RVIZ_BAG="${out%.png}_scenario.bag"
"$(catkin_find --first-only --libexec wavog_mapping wavog_simulate)" --duration 40 --out "$WAVOG_RVIZ_BAG" >/dev/null
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
# Fractions of pixels in the unknown colour and near-white (free cells).
unknown=$(convert "$out" -fuzz 4% -fill black +opaque "rgb(112,137,134)" -fill white -opaque "rgb(112,137,134)" \
  -colorspace Gray -format "%[fx:mean]" info:)
free=$(convert "$out" -colorspace Gray -threshold 97% -format "%[fx:mean]" info:)
echo "rviz-check: screenshot $out: unknown-colour fraction $unknown, near-white fraction $free"
awk -v u="$unknown" -v f="$free" 'BEGIN { exit !(u > 0.05 && f > 0.05) }' ||
  { echo "rviz-check: the map is not drawn"; exit 1; }
echo "rviz-check: map drawn"
