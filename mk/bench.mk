.PHONY: bench
## Core benchmarks: fr079 and synthetic 80 m scans at 5 and 10 cm; clamp, lazy and eager forgetting.
bench: build
	@$(BUILD)/bench/bench_core
