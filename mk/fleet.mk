# `make fleet-demo` (issue 30): three simulated vehicles, each mapper in its own process and
# namespace streaming its placed scans, one wavog_fleet node, over a private roscore. Writes
# FLEET_OUT: the fleet map and each vehicle's map (native + images), fleet_vs_vehicles.png,
# report.md / report.json (bandwidth per vehicle: stream vs changed Haar blocks (design b, one
# more playback) vs OccupancyGrid layers vs LaserScans;
# fleet CPU per vehicle-second; lag). Needs no data file. About 80 s after the build.
FLEET_OUT ?= $(ROOT)/fleet_output
FLEET_DURATION ?= 30
# FLEET_BENCH=1: also run the 8-vehicle bench (fleet-bench below) into FLEET_OUT/bench and append
# its table to report.md (a few minutes more).
FLEET_BENCH ?= 0

.PHONY: fleet-demo
fleet-demo: build
	@rm -rf $(FLEET_OUT)
	@bash -c 'source $(BUILD)/devel/setup.bash && /usr/bin/python3 $(ROOT)/scripts/fleet_demo.py \
	  $(BUILD)/devel/lib/wavog_mapping $(ROOT) $(FLEET_OUT) $(FLEET_DURATION)'
	@if [ "$(FLEET_BENCH)" = 1 ]; then bash -c 'source $(BUILD)/devel/setup.bash && \
	  /usr/bin/python3 $(ROOT)/scripts/fleet_bench.py $(BUILD)/devel/lib/wavog_mapping $(ROOT) \
	  $(FLEET_OUT)/bench $(FLEET_BENCH_DURATION) $(FLEET_BENCH_RATES)' && \
	  { echo; sed 's/^#/##/' $(FLEET_OUT)/bench/bench.md; } >> $(FLEET_OUT)/report.md; fi

# `make fleet-bench` (issue 30): eight simulated vehicles mapped by eight mappers streaming their
# placed scans, recorded into a fleet bag, played at FLEET_BENCH_RATES x real time into one
# wavog_fleet: its CPU per vehicle-second and whether it keeps up. Writes FLEET_BENCH_OUT/bench.md
# and bench.json. A few minutes after the build.
FLEET_BENCH_OUT ?= $(ROOT)/fleet_output/bench
FLEET_BENCH_DURATION ?= 20
FLEET_BENCH_RATES ?= 1,2,4

.PHONY: fleet-bench
fleet-bench: build
	@rm -rf $(FLEET_BENCH_OUT)
	@bash -c 'source $(BUILD)/devel/setup.bash && /usr/bin/python3 $(ROOT)/scripts/fleet_bench.py \
	  $(BUILD)/devel/lib/wavog_mapping $(ROOT) $(FLEET_BENCH_OUT) $(FLEET_BENCH_DURATION) \
	  $(FLEET_BENCH_RATES)'

# `make fleet-shard-bench` (issue 36): 8, 16 and 32 simulated vehicles' placed-scan streams
# (wavog_simulate --placed-scans) into 1, 2 and 4 region shards at 1x and 2x real time: CPU per
# shard, late / lost / refused, lag, kept up or not; the stream's bytes per scan as float32 and as
# 16-bit codes. Writes FLEET_BENCH_OUT/shard_bench.md and shard_bench.json. About 6 minutes after
# the build.
FLEET_SHARD_VEHICLES ?= 8,16,32
FLEET_SHARDS ?= 1,2,4
FLEET_SHARD_RATES ?= 1,2
FLEET_SHARD_DURATION ?= 10

.PHONY: fleet-shard-bench
fleet-shard-bench: build
	@mkdir -p $(FLEET_BENCH_OUT)
	@bash -c 'source $(BUILD)/devel/setup.bash && /usr/bin/python3 \
	  $(ROOT)/scripts/fleet_shard_bench.py $(BUILD)/devel/lib/wavog_mapping $(ROOT) \
	  $(FLEET_BENCH_OUT) $(FLEET_SHARD_DURATION) $(FLEET_SHARD_VEHICLES) $(FLEET_SHARDS) \
	  $(FLEET_SHARD_RATES)'
