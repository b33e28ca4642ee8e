# `make compare` (issue 6): builds wavog_compare in its own Release tree (-O3, no -march=native,
# no ROS) and runs wavog_core (clamping and forgetting), OctoMap and the dense baseline side by
# side; writes $(COMPARE_OUT)/results.md, results.csv, the disagreement PNGs (pictures.json) and
# their figures disagreement_<workload>.png (scripts/plot_compare.py, matplotlib), and the indoor
# logs without no-return clearing to $(COMPARE_OUT)/no_return_0/. Not part of
# `make test` (CI runs only the smoke test, ctest label "compare"). About 5-8 minutes on 2 cores.
BUILD_COMPARE ?= $(ROOT)/build-compare
COMPARE_OUT ?= $(ROOT)/compare_output
# OctoMap needs seconds per scan on 80 m scans, so the logs are thinned (every 12th fr079 scan,
# every 14th csail scan) and the synthetic run has 2 steps of 4 scans; see docs/compare.md.
COMPARE_ARGS ?= --stride fr079=12,csail=14 --synthetic-steps 2 --reps 5

.PHONY: compare
compare: deps
	@mkdir -p $(BUILD_COMPARE) $(COMPARE_OUT)
	@cmake -S $(ROOT) -B $(BUILD_COMPARE) -DCMAKE_BUILD_TYPE=Release -DWAVOG_BUILD_ROS=OFF \
	  $(CMAKE_ARGS) >$(BUILD_COMPARE)/configure.log || { cat $(BUILD_COMPARE)/configure.log; exit 1; }
	@cmake --build $(BUILD_COMPARE) --target wavog_compare -j$(JOBS) -- --no-print-directory
	@cd $(ROOT) && $(BUILD_COMPARE)/bin/wavog_compare --out $(COMPARE_OUT) $(COMPARE_ARGS)
	@/usr/bin/python3 $(ROOT)/scripts/plot_compare.py $(COMPARE_OUT)
	@# The indoor logs again with no-return beams ignored: how much of each structure's work the
	@# 80 m no-return rays / sectors are (README, "Reading the numbers"). About 20 s.
	@cd $(ROOT) && $(BUILD_COMPARE)/bin/wavog_compare --out $(COMPARE_OUT)/no_return_0 \
	  --workloads fr079,csail --no-return-clear 0 $(COMPARE_ARGS)
	@/usr/bin/python3 $(ROOT)/scripts/plot_compare.py $(COMPARE_OUT)/no_return_0
