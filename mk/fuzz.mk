# make fuzz: the libFuzzer harnesses of test/fuzz under ASan + UBSan (float-cast-overflow
# included, any report stops the run), each for FUZZ_SECONDS (default 60), FUZZ_JOBS at once, in
# their own core-only clang tree, which `make test-asan` shares (its core tests). A crash leaves
# its input in build-fuzz/artifacts/<harness>/.
BUILD_FUZZ ?= $(ROOT)/build-fuzz
FUZZ_SECONDS ?= 60
# The compilers are looked up when the recipe runs: on a fresh machine, install_deps.sh fuzz
# installs clang first.
FUZZ_CXX ?= $$(command -v clang++-14 || command -v clang++)
FUZZ_CC ?= $$(command -v clang-14 || command -v clang)

# make fuzz-long: a campaign of FUZZ_LONG_SECONDS per harness (default 3 h) on the same tree,
# resuming from build-fuzz/corpus/<harness>/ (what earlier runs found) and the stored seeds; ends
# with executions and coverage per harness. FUZZ_JOBS=N runs N harnesses at once (each harness is
# one process: its executions do not depend on FUZZ_JOBS while FUZZ_JOBS <= cores).
FUZZ_LONG_SECONDS ?= 10800
FUZZ_JOBS ?= $(JOBS)

.PHONY: fuzz fuzz-configure fuzz-build fuzz-long
## libFuzzer harnesses (map loader, CARMEN reader, scan integration, node, fleet and site message paths), FUZZ_SECONDS each.
fuzz: fuzz-build
	@FUZZ_JOBS=$(FUZZ_JOBS) bash $(ROOT)/scripts/run_fuzz.sh $(BUILD_FUZZ) $(FUZZ_SECONDS)

## A fuzz campaign of FUZZ_LONG_SECONDS per harness (default 3 h), resuming from earlier corpora.
fuzz-long: fuzz-build
	@FUZZ_JOBS=$(FUZZ_JOBS) bash $(ROOT)/scripts/run_fuzz.sh $(BUILD_FUZZ) $(FUZZ_LONG_SECONDS)

fuzz-build: fuzz-configure
	@bash $(ROOT)/scripts/build.sh $(BUILD_FUZZ) $(JOBS) fuzzers

fuzz-configure:
	@bash $(ROOT)/scripts/install_deps.sh fuzz
	@mkdir -p $(BUILD_FUZZ)
	@cmake -S $(ROOT) -B $(BUILD_FUZZ) -DCMAKE_CXX_COMPILER=$(FUZZ_CXX) -DCMAKE_C_COMPILER=$(FUZZ_CC) \
	  $(CMAKE_ARGS) -DWAVOG_BUILD_ROS=OFF -DWAVOG_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DWAVOG_SANITIZE="address;undefined;float-cast-overflow;fuzzer-no-link" \
	  >$(BUILD_FUZZ)/configure.log || { cat $(BUILD_FUZZ)/configure.log; exit 1; }
