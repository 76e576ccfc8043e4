# The two set-up commands of the README:
#   make demo   install deps, build, render the synthetic dynamic sequence, run SLAM, evaluate
#   make test   install deps, build, run all tests
BUILD ?= build
JOBS ?= $(shell nproc)
PSPSLAM = $(BUILD)/apps/pspslam
DEMO ?= demo_out

.PHONY: deps configure build demo test bench clean sanitize

deps:
	scripts/install-deps

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(PSPSLAM) synth --out $(DEMO)/sequence --frames 300 --bodies 3 --seed 1
	$(PSPSLAM) run --sequence $(DEMO)/sequence --out $(DEMO)/run
	$(PSPSLAM) eval --gt $(DEMO)/sequence/groundtruth.txt --est $(DEMO)/run/trajectory.txt --plot $(DEMO)/run/plots

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# ASan + UBSan and TSan builds, each running the CLI end to end (scripts/sanitize-check).
sanitize: deps
	scripts/sanitize-check

clean:
	rm -rf $(BUILD) $(DEMO)
