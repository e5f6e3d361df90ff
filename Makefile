# The two commands of the README: `make demo` and `make test`. Both set up
# what they need first (`make setup`), idempotently.
SHELL := /bin/bash
VENV := .venv
WS := .ws
PYTHON := $(CURDIR)/$(VENV)/bin/python3
# The harness (tools/tb3_harness) is on the path of make's commands, not of a user's shell.
IN_ROS := source setup.bash && export PYTHONPATH="$(CURDIR)/tools:$$PYTHONPATH" &&

.PHONY: setup apt demo test unit integration lint bench soak repeat speed-agreement clean

setup: apt $(VENV)/.ready $(WS)/devel/.ready

apt:
	@bash tools/install_apt.sh

$(VENV)/.ready: tools/requirements.txt
	/usr/bin/python3 -m venv --system-site-packages $(VENV)
	$(VENV)/bin/pip install --quiet --disable-pip-version-check -r tools/requirements.txt
	touch $@

# The workspace's copy of the root package (tb3_sim_nav) is a folder of links
# to the repo's top-level entries, not one link to the repo: rosrun searches the
# package folder with `find -L`, which would loop through $(WS) and crawl
# $(VENV). Every package of packages/ gets a link of its own beside it.
# catkin_make again whenever what it generates from could have changed.
PACKAGES := $(notdir $(wildcard packages/*))
PACKAGE_FILES := $(foreach package,$(PACKAGES),$(wildcard packages/$(package)/CMakeLists.txt packages/$(package)/package.xml \
  packages/$(package)/setup.py packages/$(package)/msg/* packages/$(package)/srv/* packages/$(package)/cfg/* \
  packages/$(package)/scripts/* packages/$(package)/nodes/* packages/$(package)/test/*.test))
$(WS)/devel/.ready: CMakeLists.txt package.xml setup.py $(wildcard cfg/*) $(wildcard scripts/*) $(wildcard test/*.test) $(PACKAGE_FILES) | $(VENV)/.ready
	[ ! -L $(WS)/src/tb3_sim_nav ] || rm $(WS)/src/tb3_sim_nav
	mkdir -p $(WS)/src/tb3_sim_nav
	find $(WS)/src -maxdepth 1 -type l -lname '$(CURDIR)/*' -delete
	find $(WS)/src/tb3_sim_nav -maxdepth 1 -type l -delete
	for entry in *; do [ "$$entry" = packages ] || ln -s "$(CURDIR)/$$entry" "$(WS)/src/tb3_sim_nav/$$entry"; done
	for package in $(PACKAGES); do ln -s "$(CURDIR)/packages/$$package" "$(WS)/src/$$package"; done
	cd $(WS) && catkin_make -DPYTHON_EXECUTABLE=$(PYTHON) -DCATKIN_ENABLE_TESTING=ON > build.log 2>&1 \
	  || { tail -40 build.log; exit 1; }
	touch $@

demo: setup
	$(IN_ROS) python3 tools/demo.py $(DEMO_ARGS)

test: setup
	$(IN_ROS) bash tools/run_tests.sh

unit: setup
	$(IN_ROS) python3 -m pytest -q test/unit $(wildcard packages/*/test)

integration: setup
	$(IN_ROS) bash tools/run_tests.sh --integration-only

# The packages as the workspace holds them: catkin_lint wants a package's
# folder named as the package, and a clone's may not be.
lint: setup
	$(IN_ROS) catkin_lint --strict -W2 $(foreach package,tb3_sim_nav $(PACKAGES),"$$(rospack find $(package))")

bench: setup
	$(IN_ROS) python3 tools/bench.py $(BENCH_ARGS)

speed-agreement: setup
	$(IN_ROS) python3 -m pytest -q -s -p no:cacheprovider test/system/test_speed_agreement.py

soak: setup
	$(IN_ROS) python3 tools/soak.py --check

# A system test file run RUNS times (default 20) beside BUSY busy cores (default 1), K its -k:
# make repeat TEST=test/system/test_navigation.py RUNS=20 [K=...] [BUSY=...]
repeat: setup
	$(IN_ROS) python3 tools/repeat.py $(TEST) $(if $(RUNS),--runs $(RUNS)) $(if $(BUSY),--busy $(BUSY)) $(if $(K),-k '$(K)')

clean:
	rm -rf $(WS) $(VENV)
