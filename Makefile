# The two commands of the README. Both install what is missing, then configure and build
# (Release, in build/), then run.
#   make demo   the main job
#   make test   every test, through ctest (FormatCheck among them: see format-check)
#   make format-check   the project's C++ files against .clang-format (clang-format 14); exits 1
#                       naming the files that differ. `make format` rewrites them.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
PIXELGYM := $(BUILD_DIR)/examples/pixelgym

.PHONY: all deps configure build demo test format-check format goldens bench clean

all: build

deps:
	scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

build: configure
	cmake --build $(BUILD_DIR) --parallel $(JOBS)

# The main job until the trainer lands: a random policy on GridWorld-v0, returns printed and a
# snapshot written to runs/demo/.
demo: build
	$(PIXELGYM) rollout GridWorld-v0 --episodes 5 --seed 0 --snapshot runs/demo/gridworld.png

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure --parallel $(JOBS)

# CI runs `make test`, which runs this same check as the ctest test FormatCheck
# (tests/examples/CMakeLists.txt): it then shows in ctest's summary beside the other tests, and a
# formatting slip does not stop the real tests from running and reporting.
format-check: deps
	scripts/format-check.sh

format: deps
	scripts/format-check.sh --fix

goldens: build
	PIXELGYM_UPDATE_GOLDENS=1 ctest --test-dir $(BUILD_DIR) -R Golden --output-on-failure
	@echo "goldens rewritten under tests/golden/: look at each PNG before committing it"

bench: build
	$(BUILD_DIR)/bench/envs_bench
	$(BUILD_DIR)/bench/engine_bench

clean:
	rm -rf $(BUILD_DIR)
