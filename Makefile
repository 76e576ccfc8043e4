# The two set-up commands of the README:
#   make demo   install what the demo needs, build the CLI only, render the synthetic dynamic
#               sequence, run SLAM on it and evaluate the trajectory against its ground truth
#   make test   install everything, build every target, run every test (ctest)
BUILD ?= build
JOBS ?= $(shell nproc)
PSPSLAM = $(BUILD)/apps/pspslam
DEMO ?= demo_out
# Ninja schedules the two-core build better than make and prints one line a file.
GENERATOR ?= Ninja
CONFIGURE = cmake -S . -B $(BUILD) -G $(GENERATOR) -DCMAKE_BUILD_TYPE=Release

.PHONY: demo test build clean sanitize

demo:
	scripts/install-deps --demo
	$(CONFIGURE) -DBUILD_TESTING=OFF
	cmake --build $(BUILD) --target pspslam_cli -j $(JOBS)
	$(PSPSLAM) synth --out $(DEMO)/sequence --frames 300 --bodies 3 --seed 1
	$(PSPSLAM) run --sequence $(DEMO)/sequence --out $(DEMO)/run
	$(PSPSLAM) eval --gt $(DEMO)/sequence/groundtruth.txt --est $(DEMO)/run/trajectory.txt --plot $(DEMO)/run/plots

build:
	scripts/install-deps
	$(CONFIGURE) -DBUILD_TESTING=ON
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# ASan + UBSan and TSan builds, each running the CLI end to end (scripts/sanitize-check).
sanitize:
	scripts/install-deps
	scripts/sanitize-check

clean:
	rm -rf $(BUILD) $(DEMO)
