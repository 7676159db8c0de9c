# The entry points; each runs the idempotent set-up first (missing Debian packages, CMake
# configure in Release, or the sanitizer build in build-sanitize/), then builds only what it needs.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
OUT ?= results/demo
export BUILD_DIR

.PHONY: setup build demo test bench sweep sanitize fuzz ci ci-short clean

setup:
	@./scripts/setup.sh

build: setup
	@cmake --build $(BUILD_DIR) -j $(JOBS)

demo: setup
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target meltwater
	@$(BUILD_DIR)/meltwater run --out $(OUT) --set 'output.formats=["vtu","preview"]'
	@$(BUILD_DIR)/meltwater plot $(OUT)

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

bench: build
	@./bench/run_benchmarks.sh $(BUILD_DIR)

# The speed–accuracy sweep (bench/sweep.py): error against cost on the validation cases, as a CSV,
# a plot and a report under bench/results/. make sweep SWEEP_ARGS=--quick for a shorter one.
PYTHON ?= /usr/bin/python3
sweep: setup
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target meltwater_python
	@$(PYTHON) bench/sweep.py --build $(BUILD_DIR) $(SWEEP_ARGS)

# Every test under AddressSanitizer and UndefinedBehaviorSanitizer (clang, no CUDA), or the ctest
# selection given: make sanitize TESTS="-L '^cli$$'".
sanitize:
	@./scripts/sanitize.sh $(TESTS)

# Each fuzz target for FUZZ_SECONDS (default 300): make fuzz FUZZ_SECONDS=60.
fuzz:
	@./scripts/fuzz.sh

# What CI runs (.ci/run): every test (make test), then make ci-short: the short form of the
# sanitizer run (the command line's and the sampler's tests and the fuzz replays, less the long
# same-results comparisons and the 2D floating rectangle, building only their programs) and of the fuzzing (a minute a target).
SANITIZE_CI_TARGETS = meltwater test_cli test_sampling test_sampling_cli fuzz_scene_reader fuzz_obj_reader fuzz_checkpoint_reader
ci: test ci-short
ci-short:
	@SANITIZE_TARGETS="$(SANITIZE_CI_TARGETS)" ./scripts/sanitize.sh -L '^(cli|sampling|sampling_cli|fuzz)$$' -E '^(same results|2D objects: a rigid rectangle floats)'
	@FUZZ_SECONDS=60 ./scripts/fuzz.sh

clean:
	@rm -rf $(BUILD_DIR) build-sanitize
