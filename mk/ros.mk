# ROS layer targets (issue 3). Neither is part of `make test`.
#   make tsan         ThreadSanitizer build in $(BUILD_TSAN); runs the core's parallel integration
#                     test (1, 2, 4 threads), then the integration, bad-input, hostile-input, bag-end,
#                     lost-scans, NDT-topics and reconfigure rostests against the node (4 scan inputs, tf, timers on 4
#                     threads; the idle flush racing the tf filters; live reconfigure).
#                     roscpp-internal reports are suppressed (test/ros/tsan.supp), and frees done by
#                     uninstrumented libraries (libroscpp) are not taken for writes
#                     (ignore_noninstrumented_modules). ~4 min on 2 cores.
#   make rviz-check   installs rviz + Xvfb (separate from `make deps`), plays 40 s of the simulated
#                     car park through launch/playback.launch (config/lms291_x4.yaml) with
#                     rviz/wavog.rviz under Xvfb and writes $(RVIZ_SHOT). About 1 minute.
BUILD_TSAN ?= $(ROOT)/build-tsan
RVIZ_SHOT ?= $(ROOT)/build/rviz_screenshot.png
ROS_ENV := export ROS_DISTRO=Debian ROS_MASTER_URI=$${ROS_MASTER_URI:-http://localhost:11311}

.PHONY: tsan rviz-check

tsan: deps
	@mkdir -p $(BUILD_TSAN)/tsan
	@cmake -S $(ROOT) -B $(BUILD_TSAN) -DCATKIN_DEVEL_PREFIX=$(BUILD_TSAN)/devel $(CMAKE_ARGS) \
	  -DWAVOG_SANITIZE=thread -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  >$(BUILD_TSAN)/configure.log || { cat $(BUILD_TSAN)/configure.log; exit 1; }
	@bash $(ROOT)/scripts/build.sh $(BUILD_TSAN) $(JOBS) wavog_mapping_node test_mapping_system \
	  test_bad_input test_hostile_input test_bag_end test_reconfigure_policy \
	  test_lost_scans test_ndt_topics test_parallel_integration
	@rm -f $(BUILD_TSAN)/tsan/report.*
	@# The core's parallel integration (worker threads, node pool) with 1, 2 and 4 threads.
	@TSAN_OPTIONS="log_path=$(BUILD_TSAN)/tsan/report second_deadlock_stack=1" \
	  $(BUILD_TSAN)/tests/test_parallel_integration >$(BUILD_TSAN)/tsan/core.log 2>&1 || \
	  { tail -20 $(BUILD_TSAN)/tsan/core.log; cat $(BUILD_TSAN)/tsan/report.* 2>/dev/null; \
	    echo "tsan: the core's parallel integration test failed"; exit 1; }
	@$(ROS_ENV); source $(BUILD_TSAN)/devel/setup.bash; \
	  export ROS_HOME=$(BUILD_TSAN)/ros_home; \
	  export TSAN_OPTIONS="log_path=$(BUILD_TSAN)/tsan/report second_deadlock_stack=1 history_size=4 ignore_noninstrumented_modules=1 suppressions=$(ROOT)/test/ros/tsan.supp"; \
	  rostest wavog_mapping mapping_node.test && rostest wavog_mapping bad_input.test && \
	  rostest wavog_mapping hostile_input.test && rostest wavog_mapping bag_end.test && \
	  rostest wavog_mapping reconfigure_policy.test && rostest wavog_mapping lost_scans.test && \
	  rostest wavog_mapping ndt_topics.test
	@if ls $(BUILD_TSAN)/tsan/report.* >/dev/null 2>&1; then \
	  cat $(BUILD_TSAN)/tsan/report.*; echo "tsan: ThreadSanitizer reports above"; exit 1; \
	else echo "tsan: no data race reported"; fi

rviz-check: build
	@command -v rviz >/dev/null && command -v Xvfb >/dev/null || \
	  { apt-get install -y -qq --no-install-recommends rviz xvfb x11-apps imagemagick >/dev/null; }
	@$(ROS_ENV); source $(BUILD)/devel/setup.bash; export ROS_HOME=$(BUILD)/ros_home; \
	  bash $(ROOT)/test/ros/rviz_screenshot.sh $(RVIZ_SHOT)
