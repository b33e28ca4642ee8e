# `make paper` (issue 17): the paper's evidence. Not part of `make test`.
#   1. wavog_paper maps ../shared/data/fr079-corrected.log.gz (or $WAVOG_DATA_DIR) with none, max,
#      clamp, forget and forget + empty-bound prior, exporting raw log-odds rasters, stats.json
#      and report.md; scripts/paper_figures.py draws fig_1_2/1_3/1_4/1_6.png from them.
#   2. wavog_evaluate runs the simulated car park with pose error (0, 2 cm / 0.2 deg,
#      5 cm / 0.5 deg) under the four policies: PAPER_OUT/noise/report.md (the noise table).
# Outputs in PAPER_OUT (default paper_output/). A few minutes after the build on 2 cores.
PAPER_OUT ?= $(ROOT)/paper_output
PAPER_BIN = $(BUILD)/devel/lib/wavog_mapping
PAPER_ZOOM ?=
PAPER_NOISE ?= 0:0,2:0.2,5:0.5
PAPER_JOBS ?= 2

.PHONY: paper
paper: deps $(BUILD)/CMakeCache.txt
	@cmake --build $(BUILD) --target wavog_paper wavog_evaluate -j$(JOBS) -- --no-print-directory
	@set -euo pipefail; start=$$(date +%s); \
	rm -rf $(PAPER_OUT); mkdir -p $(PAPER_OUT); \
	echo "paper: [1/3] mapping fr079 with none, max, clamp, forget, forget + empty-bound prior"; \
	$(PAPER_BIN)/wavog_paper --out $(PAPER_OUT) --jobs $(PAPER_JOBS) $(if $(PAPER_ZOOM),--zoom $(PAPER_ZOOM)) >/dev/null; \
	echo "paper: [2/3] drawing the figures (scripts/paper_figures.py)"; \
	/usr/bin/python3 $(ROOT)/scripts/paper_figures.py $(PAPER_OUT); \
	echo "paper: [3/3] the simulated car park under pose error ($(PAPER_NOISE), cm:deg)"; \
	$(PAPER_BIN)/wavog_evaluate --out $(PAPER_OUT)/noise --jobs $(PAPER_JOBS) --pose-noise $(PAPER_NOISE) \
	  --policy none --policy "max / unknown" --policy "clamp / unknown" --policy "forget / unknown" \
	  2>/dev/null | tail -n +2; \
	echo; echo "paper: done in $$(( $$(date +%s) - start )) s (after the build). Outputs in $(PAPER_OUT)/:"; \
	echo "  report.md, stats.json    fr079: bytes per observed cell, nodes, share at the bounds, wall width"; \
	echo "  fig_1_2.png              the four policies side by side (Fig. 1.2)"; \
	echo "  fig_1_3.png              the same zoom for the four (Fig. 1.3)"; \
	echo "  fig_1_4.png              forgetting with the empty-bound prior, map and zoom (Fig. 1.4)"; \
	echo "  fig_1_6.png              scales 0, 2, 3, 4 of the forgetting map (Fig. 1.6)"; \
	echo "  *.f32, *.known.u8, *.json   the raw log-odds rasters behind them"; \
	echo "  noise/report.md          the simulated car park with pose error (noise table at the end)"
