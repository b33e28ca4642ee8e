#!/usr/bin/env bash
# Runs the registered tests of a build directory with ctest (extra arguments go to ctest) and
# ends with a plain "N passed, N failed" line. Exit status: non-zero if any test failed.
set -uo pipefail
build=${1:?usage: run_tests.sh BUILD_DIR [ctest args]}
shift
export PATH=/usr/bin:$PATH
if [ -f "$build/devel/setup.bash" ]; then
  # ROS's env hooks read unset variables: source them without nounset.
  set +u
  # shellcheck disable=SC1091
  source "$build/devel/setup.bash"
  set -u
fi
# rostests start their own roscore on a free port; keep ROS logs inside the build tree.
export ROS_HOME=${ROS_HOME:-$build/ros_home}
export ROS_LOG_DIR=${ROS_LOG_DIR:-$build/ros_home/log}
log=$build/ctest.log
( cd "$build" && ctest --output-on-failure --timeout 1200 "$@" ) 2>&1 | tee "$log"
status=${PIPESTATUS[0]}
total=$(grep -Eo 'tests passed, [0-9]+ tests? failed out of [0-9]+' "$log" | tail -1 | grep -Eo '[0-9]+$')
failed=$(grep -Eo 'tests passed, [0-9]+ tests? failed' "$log" | tail -1 | grep -Eo '[0-9]+' | head -1)
if [ -z "${total:-}" ]; then
  echo "0 passed, 1 failed (ctest did not run: see $log)"
  exit 1
fi
echo "$((total - failed)) passed, ${failed} failed"
[ "$status" -eq 0 ] && [ "$failed" -eq 0 ]
