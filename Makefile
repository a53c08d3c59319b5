# Top-level entry points; the README's two commands are `make run` and `make test`.
# Each installs what is missing (scripts/install-deps.sh), then builds with CMake.

BUILD ?= build
ASAN_BUILD ?= build-asan
JOBS ?= 2
EXAMPLE ?= studies/case-a.json

.PHONY: all deps build run test test-asan clean

all: build

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPRSM_WERROR=ON >/dev/null
	@cmake --build $(BUILD) -j$(JOBS)

# The main job: for now the nominal analysis of an example design.
run: build
	$(BUILD)/prsm analyze $(EXAMPLE) --format text

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)
	@$(MAKE) --no-print-directory test-asan

# Unit tests again under AddressSanitizer + UndefinedBehaviorSanitizer.
test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DPRSM_SANITIZE=ON -DPRSM_WERROR=ON >/dev/null
	@cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j$(JOBS) -L unit

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
