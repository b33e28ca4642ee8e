# make soak (issue 16; not part of `make test`): the simulated car park (wavog_simulate, four
# LMS-291 at 40 Hz each) played through the node for SOAK_MINUTES simulated minutes (default 90,
# the paper's run length) at SOAK_RATE x real time (rosbag play -r, use_sim_time), resident memory
# and the map's bytes sampled every simulated minute. Writes $(SOAK_DIR)/soak.csv, soak.png and
# soak.txt (slope per hour, scans lost: must be 0). Exit status non-zero if a scan was lost.
SOAK_MINUTES ?= 90
SOAK_RATE ?= 2
SOAK_DIR ?= $(BUILD)/soak

.PHONY: soak
## Soak: the simulated car park through the node, SOAK_MINUTES (90) at SOAK_RATE (2) x real time.
soak: build
	@bash $(ROOT)/scripts/soak.sh $(BUILD) $(SOAK_DIR) $(SOAK_MINUTES) $(SOAK_RATE)
