# Top-level entry points; the README's two commands are `make run` and `make test`.
# Each installs what is missing (scripts/install-deps.sh), then builds with CMake.

BUILD ?= build
ASAN_BUILD ?= build-asan
TSAN_BUILD ?= build-tsan
JOBS ?= 2
EXAMPLE ?= studies/case-a.json

.PHONY: all deps build run example test test-asan test-tsan clean

all: build

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPRSM_WERROR=ON >/dev/null
	@cmake --build $(BUILD) -j$(JOBS)

# The main job: the service with its web form, http://127.0.0.1:8080/ (database ./prsm.db);
# SERVE_ARGS passes options, e.g. make run SERVE_ARGS="--port 9000 --workers 2".
SERVE_ARGS ?=
run: build
	$(BUILD)/prsm serve $(SERVE_ARGS)

# The nominal analysis of an example design, as a one-page summary.
example: build
	$(BUILD)/prsm analyze $(EXAMPLE) --format text

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)
	@$(MAKE) --no-print-directory test-asan
	@$(MAKE) --no-print-directory test-tsan

# Unit tests again under AddressSanitizer + UndefinedBehaviorSanitizer.
test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DPRSM_SANITIZE=ON -DPRSM_WERROR=ON >/dev/null
	@cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j$(JOBS) -L unit

# Unit tests again under ThreadSanitizer: data races (a cancel flag, a worker's claim) fail the run;
# the tests that never start a thread (label single_thread, tests/CMakeLists.txt) are left out.
test-tsan: deps
	@cmake -S . -B $(TSAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DPRSM_TSAN=ON -DPRSM_WERROR=ON >/dev/null
	@cmake --build $(TSAN_BUILD) -j$(JOBS)
	cd $(TSAN_BUILD) && TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" ctest --output-on-failure -j$(JOBS) -L unit -LE single_thread

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(TSAN_BUILD)
