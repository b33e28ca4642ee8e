#!/usr/bin/env bash
# ctest entry build_all_holds_no_tests (issue 41): `make build` builds no test. In a build tree of
# the Makefile generator, CMakeFiles/Makefile2 lists what `all` builds ("all: CMakeFiles/<t>.dir/all");
# no test_*, bench_*, room_scene, wavog_test_support or the fleet test's bag may be among them.
set -euo pipefail
build=${1:?usage: check_all_target.sh BUILD_DIR}
makefile=$build/CMakeFiles/Makefile2
[ -f "$makefile" ] || { echo "check_all_target: $makefile missing (not a Makefile build tree)"; exit 1; }
in_all=$(sed -n 's|^all: CMakeFiles/\([^/]*\)\.dir/all$|\1|p' "$makefile" | sort -u)
[ -n "$in_all" ] || { echo "check_all_target: no target of all found in $makefile"; exit 1; }
tests=$(echo "$in_all" | grep -E '^(test_|bench_|room_scene$|wavog_test_support$|wavog_fleet_test_bag$)' || true)
echo "check_all_target: $(echo "$in_all" | wc -l) targets in all"
if [ -n "$tests" ]; then
  echo "check_all_target: tests built by make build (all):"
  echo "$tests" | sed 's/^/  /'
  exit 1
fi
echo "check_all_target: no test in all"
