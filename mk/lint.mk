# `make lint` (issue 35): the package as catkin_lint (Debian's catkin-lint) checks released ROS
# packages, at -W1 (errors and warnings; -W2 adds style notices): --strict makes any of them fail
# the target. Offline: nothing is downloaded. The few constructs it cannot follow carry its
# `#catkin_lint:` pragma with the reason beside them (git grep catkin_lint). A second or so.
.PHONY: lint
lint: deps
	@catkin_lint -W1 --strict --offline -q $(ROOT) && echo "lint: catkin_lint -W1 clean"
