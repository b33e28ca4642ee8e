.PHONY: bench
## Core benchmarks: fr079 and synthetic 80 m scans at 5 and 10 cm; clamp, lazy and eager forgetting.
bench: build
	@bash $(ROOT)/scripts/build.sh $(BUILD) $(JOBS) bench_core
	@# Repetitions of the variants interleaved at random, so a drift of the machine's speed
	@# does not bias the ratios.
	@$(BUILD)/bench/bench_core --benchmark_enable_random_interleaving=true
