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
# The real-data tests this build left out (cmake/real_data.cmake): say so on the last lines.
missing_list=$build/real_data_missing.txt
if [ -s "$missing_list" ]; then
  n_missing=$(wc -l <"$missing_list")
  echo "${n_missing} real-data test(s) did not run: their logs and bags were not found (WAVOG_DATA_DIR, else ../shared/data beside the repository):"
  sed 's/^/  /' "$missing_list"
  echo "To run them, put the public data sets there (README, 'Test data': where to get each) and run make test again."
  if [ "${WAVOG_REQUIRE_DATA:-0}" = 1 ]; then
    echo "WAVOG_REQUIRE_DATA=1: every real-data test must run"
    exit 1
  fi
fi
[ "$status" -eq 0 ] && [ "$failed" -eq 0 ]
