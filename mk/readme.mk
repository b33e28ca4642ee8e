# `make readme-check` (issue 13): runs the commands of README.md's code blocks that are marked
# <!-- check ... --> (scripts/check_readme_commands.sh), after the two set-up commands: it runs
# `make demo` first when demo_output/ is missing, and needs a built tree (make build / make test).
# Not part of `make test`. About 2 minutes.
.PHONY: readme-check
readme-check: build
	@[ -e $(ROOT)/demo_output/scenario.bag ] || $(MAKE) --no-print-directory demo
	@timeout 1200 bash $(ROOT)/scripts/check_readme_commands.sh
