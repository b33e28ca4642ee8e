# Entry points. `make test` is the project's test command (README, .ci/run).
SHELL := /bin/bash
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
BUILD ?= $(ROOT)/build
JOBS ?= $(shell nproc)
# Debian's python (with catkin_pkg) must come before the pyenv shim.
export PATH := /usr/bin:$(PATH)
CMAKE_ARGS := -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_ENABLE_TESTING=ON
# ccache, where the machine has it, shortens rebuilds (not installed by deps; optional).
ifneq ($(shell command -v ccache 2>/dev/null),)
CMAKE_ARGS += -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache
export CCACHE_BASEDIR ?= $(abspath $(ROOT)/..)
endif

.PHONY: deps build test test-asan bench clean

deps:
	@bash $(ROOT)/scripts/install_deps.sh

$(BUILD)/CMakeCache.txt: | deps
	@mkdir -p $(BUILD)
	@cmake -S $(ROOT) -B $(BUILD) -DCATKIN_DEVEL_PREFIX=$(BUILD)/devel $(CMAKE_ARGS) >$(BUILD)/configure.log \
	  || { cat $(BUILD)/configure.log; exit 1; }

# What a user runs (the `all` target: node, nodelet, tools; no test: cmake/test_targets.cmake).
# A build that left real-data tests out configures again, in case the data has come since.
build: deps $(BUILD)/CMakeCache.txt
	@if [ -s $(BUILD)/real_data_missing.txt ]; then cmake $(BUILD) >$(BUILD)/configure.log \
	  || { cat $(BUILD)/configure.log; exit 1; }; fi
	@bash $(ROOT)/scripts/build.sh $(BUILD) $(JOBS) all
	@# rosrun skips the package's own build/: bin/ (made here, not in git) is where it finds them.
	@ln -sfn $(BUILD)/devel/lib/wavog_mapping $(ROOT)/bin

## Every test (core gtests and rostests), built here; ends with "N passed, N failed".
test: build
	@bash $(ROOT)/scripts/build.sh $(BUILD) $(JOBS)
	@bash $(ROOT)/scripts/run_tests.sh $(BUILD)

## The core tests under AddressSanitizer + UndefinedBehaviorSanitizer, in the clang tree of
## `make fuzz` (mk/fuzz.mk): one sanitized build of the core serves both.
test-asan: fuzz-configure
	@bash $(ROOT)/scripts/build.sh $(BUILD_FUZZ) $(JOBS) core_tests
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  bash $(ROOT)/scripts/run_tests.sh $(BUILD_FUZZ) -L core

clean:
	rm -rf $(BUILD) $(BUILD_FUZZ)

# Further targets (bench, demo, compare, ...) live in mk/*.mk, one file per part.
-include $(ROOT)/mk/*.mk
