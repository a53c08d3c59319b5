# Top-level entry points; the README's two commands are `make run` and `make test`.
# Each installs what is missing (scripts/install-deps.sh), then builds with CMake.

BUILD ?= build
ASAN_BUILD ?= build-asan
JOBS ?= 2
EXAMPLE ?= studies/case-a.json

.PHONY: all deps build run example test test-asan clean

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

# Unit tests again under AddressSanitizer + UndefinedBehaviorSanitizer.
test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DPRSM_SANITIZE=ON -DPRSM_WERROR=ON >/dev/null
	@cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j$(JOBS) -L unit

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
