# The two commands of the README. Both install what is missing, then configure and build
# (Release, in build/), then run.
#   make demo   the main job
#   make test   every test, through ctest (FormatCheck among them: see format-check)
#   make test-egl    every test again with OpenGL through EGL (PIXELGYM_GL=egl), on the build of
#                    make test (CI runs it after `make test`)
#   make test-no-osmesa   builds without OSMesa (-DPIXELGYM_OSMESA=OFF, as for a Mesa >= 25.1) in
#                    build-no-osmesa/ and runs the render and task tests there, on EGL (CI runs it)
#   make test-asan   every test, built with AddressSanitizer and UBSan in build-asan/ (CI runs it
#                    after `make test`)
#   make test-tsan   the tests labelled threads, built with ThreadSanitizer in build-tsan/ (CI runs
#                    it after test-asan)
#   make fuzz        builds the fuzz targets with libFuzzer (clang) in build-fuzz/ and fuzzes one:
#                    FUZZ_TARGET=urdf FUZZ_SECONDS=600 (docs/reliability.md)
#   make install     installs the Release build (cmake --install build; PREFIX=/usr/local unless
#                    given): libraries, headers, CMake package, tool, assets, Python package
#   make wheel       builds a wheel of the Python package into dist/ (pixelgym-VERSION-TAG.whl), for
#                    Debian's /usr/bin/python3 from the Release build in build/, or for another
#                    Python with PYTHON=/path/to/python3 (in build-wheel/TAG/): for
#                    `pip install dist/pixelgym-*.whl` into that Python's venv (docs/python.md)
#   make deb         builds the Debian package in build-deb/ (prefix /usr, tests off):
#                    build-deb/pixelgym_VERSION_ARCH.deb, for `apt install ./build-deb/pixelgym_*.deb`
#   make bench-report   builds, then runs the benchmarks beside the reference programs of
#                       ../shared/peers in interleaved rounds (REPEATS=5, about 17 minutes here) and
#                       writes bench/RESULTS.md and README.md's headline figures (bench/README.md)
#   make format-check   the project's C++ files against .clang-format (clang-format 14); exits 1
#                       naming the files that differ. `make format` rewrites them.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
PIXELGYM := $(BUILD_DIR)/examples/pixelgym

.PHONY: all deps configure build demo test test-egl test-no-osmesa test-asan test-tsan fuzz install wheel deb format-check format goldens bench bench-report clean

all: build

deps:
	scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE)

build: configure
	cmake --build $(BUILD_DIR) --parallel $(JOBS)

# The main job: PPO from pixels only (64x64 anti-aliased grey frames, 3 stacked, each action held
# for 8 control steps as dm_control's pixel benchmarks do) on CartPoleBalance-v1 (the cart-pole
# drawn with a thick, dark pole that shows in small grey frames) for 10 minutes of wall time, into
# a fresh runs/demo/ (the previous demo run is replaced). The config sets gamma 0.95 per env step,
# which with action_repeat 8 discounts like 0.994 per control step (PPO's default 0.99 would be
# 0.9987: a horizon of 8 s, whose values the CNN learned too poorly).
DEMO_TRAIN := train CartPoleBalance-v1 --set obs_mode=pixels --set width=64 --set height=64 \
  --set msaa=4 --set action_repeat=8 --wrap grayscale --wrap frame_stack=3 \
  --config action_repeat_8 --minutes 10 --out runs/demo
demo: build
	rm -rf runs/demo
	$(PIXELGYM) $(DEMO_TRAIN)

test: build
	ctest --test-dir $(BUILD_DIR) --output-on-failure --parallel $(JOBS)

# The same tests drawing through EGL: PIXELGYM_GL=egl makes every renderer and env of
# render_backend=auto use it (tests of OSMesa itself ask for it by name). The frames must be the
# same bytes (tests/envs/render_backends_test.cc), so the goldens hold.
test-egl: build
	PIXELGYM_GL=egl ctest --test-dir $(BUILD_DIR) --output-on-failure --parallel $(JOBS)

# A build without OSMesa (what a distribution whose Mesa no longer ships it builds): the render and
# task tests (ctest label render_tasks: tests/render and tests/envs) must pass drawing through EGL;
# the tests of OSMesa itself skip, saying so.
NO_OSMESA_BUILD_DIR ?= build-no-osmesa
test-no-osmesa: deps
	cmake -S . -B $(NO_OSMESA_BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DPIXELGYM_OSMESA=OFF \
	  -DPIXELGYM_BUILD_BENCH=OFF -DPIXELGYM_BUILD_PYTHON=OFF
	cmake --build $(NO_OSMESA_BUILD_DIR) --parallel $(JOBS) --target render_task_tests
	ctest --test-dir $(NO_OSMESA_BUILD_DIR) -L render_tasks --output-on-failure --parallel $(JOBS)

# AddressSanitizer (with LeakSanitizer) and UndefinedBehaviorSanitizer over every test, the fuzz
# corpora's replays (Fuzz.*) among them, in a Debug build at -O1 (asserts on; warnings are not
# errors here: GCC's are false alarms under the sanitizers' instrumentation). lsan.supp names the
# third-party leaks suppressed, each with its reason. The Python binding's tests run with ASan's
# runtime preloaded into the interpreter (tests/python/CMakeLists.txt says how and why). The
# sanitizer and fuzz builds link pixelgym's libraries statically, as they were checked (the
# installable shared libraries are the Release build's: the consumer test runs there).
# intercept_tls_get_addr=0: libOSMesa is dlopen()ed, so its thread-locals are dynamic TLS, and
# GCC 12's ASan guesses each such block's bounds from a glibc 2.19 header that glibc 2.36 no
# longer writes; where a block happens to start 16 bytes past a page boundary, LeakSanitizer
# reads a garbage range and its tracer crashes at exit (docs/reliability.md).
# ONEDNN_MAX_CPU_ISA: on CPUs with AMX (Intel Sapphire Rapids and later) LibTorch's oneDNN 2.6
# picks AMX convolution kernels, and creating one read past the end of a heap block; under ASan's
# allocator that read crossed into an unmapped page (a SEGV inside libdnnl.so in the drqv2
# training test), so the ASan suite caps oneDNN at AVX-512 with BF16 unless you set it
# (docs/reliability.md).
ONEDNN_MAX_CPU_ISA ?= AVX512_CORE_BF16
ASAN_BUILD_DIR ?= build-asan
test-asan: deps
	cmake -S . -B $(ASAN_BUILD_DIR) -DCMAKE_BUILD_TYPE=Debug -DPIXELGYM_SANITIZE=address \
	  -DPIXELGYM_BUILD_BENCH=OFF -DPIXELGYM_WERROR=OFF -DPIXELGYM_BUILD_PYTHON=ON \
	  -DPIXELGYM_SHARED_LIBS=OFF
	cmake --build $(ASAN_BUILD_DIR) --parallel $(JOBS)
	ONEDNN_MAX_CPU_ISA="$(ONEDNN_MAX_CPU_ISA)" \
	ASAN_OPTIONS="detect_stack_use_after_return=0 strict_init_order=1 intercept_tls_get_addr=0 $(ASAN_OPTIONS)" \
	UBSAN_OPTIONS="print_stacktrace=1 halt_on_error=1 $(UBSAN_OPTIONS)" \
	LSAN_OPTIONS="suppressions=$(CURDIR)/lsan.supp print_suppressions=0 $(LSAN_OPTIONS)" \
	  ctest --test-dir $(ASAN_BUILD_DIR) --output-on-failure --parallel $(JOBS)

# ThreadSanitizer over the threading tests (ctest label threads; a test joins with
# `pixelgym_add_test(... LABELS threads)`). Only the tests labelled threads are built. tsan.supp
# names the third-party libraries whose reports are suppressed, each with its reason, and why
# detect_deadlocks=0 (llvmpipe's LLVM JIT overflows TSan's lock table).
TSAN_BUILD_DIR ?= build-tsan
test-tsan: deps
	cmake -S . -B $(TSAN_BUILD_DIR) -DCMAKE_BUILD_TYPE=Debug -DPIXELGYM_SANITIZE=thread \
	  -DPIXELGYM_BUILD_BENCH=OFF -DPIXELGYM_WERROR=OFF -DPIXELGYM_SHARED_LIBS=OFF
	cmake --build $(TSAN_BUILD_DIR) --parallel $(JOBS) --target threads_tests
	TSAN_OPTIONS="suppressions=$(CURDIR)/tsan.supp halt_on_error=1 detect_deadlocks=0 $(TSAN_OPTIONS)" \
	  ctest --test-dir $(TSAN_BUILD_DIR) -L threads --output-on-failure --parallel $(JOBS)

# libFuzzer over one fuzz target (fuzz/NAME_fuzz.cc) for FUZZ_SECONDS, growing fuzz/corpus/NAME/
# in place; a finding is written to build-fuzz/findings/NAME/ (fix it, and add the file to the
# corpus: every build replays it). Built with clang, everything instrumented for coverage, ASan and
# UBSan.
FUZZ_BUILD_DIR ?= build-fuzz
FUZZ_TARGET ?= urdf
FUZZ_SECONDS ?= 600
FUZZ_TIMEOUT ?= 10
fuzz: deps
	cmake -S . -B $(FUZZ_BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
	  -DPIXELGYM_FUZZ=ON -DPIXELGYM_BUILD_BENCH=OFF -DPIXELGYM_BUILD_PYTHON=OFF \
	  -DPIXELGYM_SHARED_LIBS=OFF
	cmake --build $(FUZZ_BUILD_DIR) --parallel $(JOBS) --target $(FUZZ_TARGET)_fuzz
	mkdir -p $(FUZZ_BUILD_DIR)/findings/$(FUZZ_TARGET)
	LSAN_OPTIONS="suppressions=$(CURDIR)/lsan.supp print_suppressions=0 $(LSAN_OPTIONS)" \
	  $(FUZZ_BUILD_DIR)/fuzz/$(FUZZ_TARGET)_fuzz -max_total_time=$(FUZZ_SECONDS) -timeout=$(FUZZ_TIMEOUT) \
	  -print_final_stats=1 \
	  -artifact_prefix=$(FUZZ_BUILD_DIR)/findings/$(FUZZ_TARGET)/ $(FUZZ_FLAGS) \
	  fuzz/corpus/$(FUZZ_TARGET)

# CI runs `make test`, which runs this same check as the ctest test FormatCheck
# (tests/examples/CMakeLists.txt): it then shows in ctest's summary beside the other tests, and a
# formatting slip does not stop the real tests from running and reporting.
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD_DIR) --prefix $(PREFIX)

# pip runs the in-tree backend (pyproject.toml, python/backend/) offline: it builds the module and
# the libraries it loads, and packs them with the assets. Debian's Python reuses build/ (configured
# for it); another Python gets a build folder of its own, build-wheel/TAG.
PYTHON ?= /usr/bin/python3
wheel: configure
	$(PYTHON) -m pip wheel . --no-deps --no-build-isolation --no-index --wheel-dir dist \
	  $(if $(filter /usr/bin/python3,$(PYTHON)),--config-settings build-dir=$(BUILD_DIR))

DEB_BUILD_DIR ?= build-deb
deb: deps
	cmake -S . -B $(DEB_BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
	  -DPIXELGYM_BUILD_TESTS=OFF -DPIXELGYM_BUILD_BENCH=OFF
	cmake --build $(DEB_BUILD_DIR) --parallel $(JOBS)
	cd $(DEB_BUILD_DIR) && cpack -G DEB

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

REPEATS ?= 5
bench-report: build
	/usr/bin/python3 bench/report.py --build $(BUILD_DIR) --repeats $(REPEATS)

clean:
	rm -rf $(BUILD_DIR)
