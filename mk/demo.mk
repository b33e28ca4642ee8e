# `make demo` (issue 5): the paper's vehicle scenario, simulated with ground truth, mapped with the
# default configuration (exponential forgetting) and evaluated under every update policy.
# Installs what it needs (deps), builds the tools it runs, then, in DEMO_OUT:
#   scenario.bag         wavog_simulate: four LMS-291 at 40 Hz on a truck in a car park, 60 s
#   world.yaml, ground_truth/   the scenario as a world file and its rasterised truth every 10 s
#   map/                 wavog_offline with config/default.yaml: map_s<scale>.png/.pgm/.yaml
#                        (scales 0, 2, 3, 4), snapshots/ every 15 s, map.wavog, summary.json
#                        (through the core directly when wavog_offline is not built)
#   report.md, summary.json, figure_data/   wavog_evaluate --ndt (the figures' data: maps, CSV)
#   policies.png, departure.png, arrival.png, ndt_wall_distance.png   scripts/plot_evaluation.py
#                        (matplotlib); --ndt adds a few % of CPU time (63.0 s user without, 63.1-65.2 s with)
# About 1-2 minutes after the build on 2 cores.
DEMO_OUT ?= $(ROOT)/demo_output
DEMO_SEED ?= 1
DEMO_BIN = $(BUILD)/devel/lib/wavog_mapping
DEMO_TOPICS = scan_front_left,scan_front_right,scan_rear_left,scan_rear_right

.PHONY: demo
demo: deps $(BUILD)/CMakeCache.txt
	@cmake --build $(BUILD) --target wavog_simulate wavog_evaluate -j$(JOBS) -- --no-print-directory
	@cmake --build $(BUILD) --target wavog_offline -j$(JOBS) -- --no-print-directory >/dev/null 2>&1 \
	  || echo "demo: wavog_offline not available; mapping through the core directly"
	@set -euo pipefail; start=$$(date +%s); \
	rm -rf $(DEMO_OUT); mkdir -p $(DEMO_OUT); \
	echo "demo: [1/3] simulating the car park (seed $(DEMO_SEED))"; \
	$(DEMO_BIN)/wavog_simulate --seed $(DEMO_SEED) --out $(DEMO_OUT)/scenario.bag \
	  --write-world $(DEMO_OUT)/world.yaml --truth-dir $(DEMO_OUT)/ground_truth 2>&1 | tr '\r' '\n' | tail -2; \
	echo "demo: [2/3] mapping it with config/default.yaml (exponential forgetting)"; \
	core_maps=""; offline_summary=""; \
	if [ -x $(DEMO_BIN)/wavog_offline ]; then \
	  $(DEMO_BIN)/wavog_offline --config $(ROOT)/config/default.yaml --topics $(DEMO_TOPICS) \
	    --scale 0,2,3,4 --snapshot-every 15 --no-progress --out $(DEMO_OUT)/map $(DEMO_OUT)/scenario.bag; \
	  offline_summary="--offline-summary $(DEMO_OUT)/map/summary.json"; \
	else core_maps="--core-maps $(DEMO_OUT)/map"; fi; \
	echo "demo: [3/3] evaluating every update policy against the ground truth"; \
	$(DEMO_BIN)/wavog_evaluate --seed $(DEMO_SEED) --ndt --out $(DEMO_OUT) $$core_maps $$offline_summary; \
	/usr/bin/python3 $(ROOT)/scripts/plot_evaluation.py $(DEMO_OUT); \
	echo; echo "demo: done in $$(( $$(date +%s) - start )) s (after the build). Outputs in $(DEMO_OUT)/:"; \
	echo "  report.md             the policy comparison table (also summary.json)"; \
	echo "  policies.png          final maps of every policy side by side"; \
	echo "  departure.png         a departed car's occupancy against time, per policy"; \
	echo "  arrival.png           an arrived car's occupancy against time, per policy"; \
	echo "  ndt_wall_distance.png per policy, how far from the true walls the occupied cells' centres and the NDT means lie"; \
	echo "  figure_data/          the figures' data (final map per policy, responses.csv, ndt_wall_distance.csv; scripts/plot_evaluation.py)"; \
	echo "  map/map_s*.png        the default (forgetting) map at scales 0, 2, 3, 4 (+ PGM/YAML)"; \
	echo "  scenario.bag          the simulated rosbag (rosbag play it to the node)"; \
	echo "  world.yaml, ground_truth/   the scenario and its true occupancy"
