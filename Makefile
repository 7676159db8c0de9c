# Three entry points; each runs the idempotent set-up first (missing Debian packages, CMake
# configure in Release), then builds only what it needs.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
OUT ?= results/demo
export BUILD_DIR

.PHONY: setup build demo test bench clean

setup:
	@./scripts/setup.sh

build: setup
	@cmake --build $(BUILD_DIR) -j $(JOBS)

demo: setup
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target meltwater
	@$(BUILD_DIR)/meltwater run --out $(OUT)

test: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

bench: build
	@./bench/run_benchmarks.sh $(BUILD_DIR)

clean:
	@rm -rf $(BUILD_DIR)
