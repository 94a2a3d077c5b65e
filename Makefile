# Farfield's front door. `make demo` and `make test` work on a fresh Debian 12 machine: both install the Debian
# packages the project needs first (scripts/install-deps.sh, through apt-get; root or sudo).
JOBS        ?= $(shell nproc 2>/dev/null || echo 2)
BUILD       ?= build/release
BUILD_ASAN  ?= build/asan
BUILD_FUZZ  ?= build/fuzz
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?=
CMAKE_FLAGS ?=
# Real windows for the viewer's tests come from Xvfb when it is installed and no display is set. -noreset: by default
# Xvfb resets when its last client disconnects, and a test connecting during the reset fails to open the display.
XVFB        := $(shell if [ -z "$$DISPLAY" ] && command -v xvfb-run >/dev/null 2>&1; then echo "xvfb-run -a -s '-screen 0 1280x1024x24 -noreset'"; fi)

.PHONY: all deps configure build build-cli demo test test-asan fuzz bench dist clean

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DFF_BUILD_TESTS=ON -DFF_BUILD_BENCH=ON $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# The demo needs only the command-line tool (the tests build the rest).
build-cli: configure
	@cmake --build $(BUILD) -j $(JOBS) --target farfield_cli

demo: build-cli
	@bash scripts/demo.sh $(BUILD)/bin/farfield out/demo

# FF_GL_BARRIER_CHECK=1: every test's GL calls are checked for missing memory barriers (gpu/gl_barrier_check.h); a
# hazard it prints fails the test (tests/CMakeLists.txt).
test: build
	@cd $(BUILD) && FF_GL_BARRIER_CHECK=1 $(XVFB) ctest --output-on-failure -j $(JOBS) --timeout 900

# intercept_tls_get_addr=0: GCC 12's sanitizer runtime (Debian 12's) takes a dynamic TLS block that malloc placed 16
# bytes past a page boundary for a pre-2.25 glibc block with a header, reads the two words before it as the block's
# bounds, and LeakSanitizer's tracer dies scanning them at exit ("Tracer caught signal 11"), in whichever test's
# allocations happen to put a GL driver's TLS block there (docs/DESIGN-NOTES.md, Sanitizer build). Without the
# interceptor the blocks are ordinary heap blocks, reached through the thread's DTV, and still scanned.
# scripts/lsan_tls_repro.sh shows the crash and the option's fix on a ten-line program.
test-asan: deps
	@cmake -S . -B $(BUILD_ASAN) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFF_SANITIZE=ON -DFF_BUILD_BENCH=OFF $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(BUILD_ASAN) -j $(JOBS)
	@cd $(BUILD_ASAN) && ASAN_OPTIONS=detect_leaks=1:intercept_tls_get_addr=0 FF_GL_BARRIER_CHECK=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp UBSAN_OPTIONS=print_stacktrace=1 $(XVFB) ctest --output-on-failure -j $(JOBS) --timeout 1800

# libFuzzer targets (clang, ASan + UBSan), one per input format (docs/FUZZING.md): seeds the corpora, runs each target
# for FUZZ_SECONDS (FUZZ_TARGETS="osm dem" for some), prints executions, exec/s, coverage and crashes; fails on a crash.
fuzz: deps
	@CC=clang CXX=clang++ cmake -S . -B $(BUILD_FUZZ) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DFF_FUZZ=ON -DFF_BUILD_TESTS=OFF \
	  -DFF_BUILD_BENCH=OFF $(CMAKE_FLAGS) >/dev/null
	@cmake --build $(BUILD_FUZZ) -j $(JOBS) --target fuzz
	@bash fuzz/seed_corpus.sh $(BUILD_FUZZ) >/dev/null
	@bash fuzz/run_fuzzers.sh $(BUILD_FUZZ) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

bench: build
	@bash scripts/bench.sh $(BUILD)/bin out/bench

# The release tarball for a machine without Debian's development packages (a bare GPU node): the tool, the shared
# libraries it loads but glibc, libstdc++ and the GL dispatch, PROJ's and GDAL's data, in out/dist
# (scripts/make_dist.sh; scripts/check_dist.sh proves one on a minimal Debian 12).
dist: build-cli
	@bash scripts/make_dist.sh $(BUILD)/bin/farfield out/dist

clean:
	rm -rf build out
