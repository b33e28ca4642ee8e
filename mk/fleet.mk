# `make fleet-demo` (issue 30): three simulated vehicles, each mapper in its own process and
# namespace streaming its placed scans, one wavog_fleet node, over a private roscore. Writes
# FLEET_OUT: the fleet map and each vehicle's map (native + images), fleet_vs_vehicles.png,
# report.md / report.json (bandwidth per vehicle: stream vs OccupancyGrid layers vs LaserScans;
# fleet CPU per vehicle-second; lag). Needs no data file. About a minute after the build.
FLEET_OUT ?= $(ROOT)/fleet_output
FLEET_DURATION ?= 30

.PHONY: fleet-demo
fleet-demo: build
	@rm -rf $(FLEET_OUT)
	@bash -c 'source $(BUILD)/devel/setup.bash && /usr/bin/python3 $(ROOT)/scripts/fleet_demo.py \
	  $(BUILD)/devel/lib/wavog_mapping $(ROOT) $(FLEET_OUT) $(FLEET_DURATION)'
