# `make install-check` (issue 13): the catkin-workspace way from scratch, as a user does it: a fresh
# workspace in $(INSTALL_CHECK_WS) with this repository linked under src/, `catkin_make install`,
# then test/install/install_test.sh on its install space (files, the core API, mapping.launch,
# mapping_node.launch and fixed_frame_laser from the install space alone). A whole second build:
# not part of `make test` (whose ctest entry install_space tests `cmake --install` of build/).
# About 10 minutes on 2 cores without ccache. The workspace lies outside the repository: inside,
# the link under src/ would make a loop that roslaunch's file search follows.
INSTALL_CHECK_WS ?= $(or $(TMPDIR),/tmp)/wavog_install_check

.PHONY: install-check
install-check: deps
	@rm -rf $(INSTALL_CHECK_WS); mkdir -p $(INSTALL_CHECK_WS)/src
	@ln -s $(ROOT) $(INSTALL_CHECK_WS)/src/wavog_mapping
	@cd $(INSTALL_CHECK_WS) && catkin_make install -j$(JOBS) $(CMAKE_ARGS) -DCMAKE_BUILD_TYPE=Release \
	  >$(INSTALL_CHECK_WS)/catkin_make.log 2>&1 || { tail -50 $(INSTALL_CHECK_WS)/catkin_make.log; exit 1; }
	@bash $(ROOT)/test/install/install_test.sh --prefix $(INSTALL_CHECK_WS)/install
