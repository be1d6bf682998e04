# arcsim build. `make` builds bin/arcsim; `make check` installs what is missing, builds and runs every test
# (optimised and under AddressSanitizer + UndefinedBehaviorSanitizer); `make demo` simulates and renders the
# default scene; `make bench` runs the benchmarks.

CXX      ?= g++
PKGS     := eigen3 nlopt jsoncpp libpng osmesa
DEPS_OK  := $(shell pkg-config --exists $(PKGS) 2>/dev/null && test -f /usr/include/suitesparse/cholmod.h && echo yes)

# CHOLMOD (SuiteSparse 5 on Debian 12) ships no pkg-config file.
CHOLMOD_CFLAGS := -isystem /usr/include/suitesparse
CHOLMOD_LIBS   := -lcholmod -lamd -lcolamd -lsuitesparseconfig

WARN     := -Wall -Wextra -Wshadow=local -Wno-unused-parameter
# Dependency headers are system headers: their own warnings (Eigen's false maybe-uninitialized) are not ours.
BASEFLAGS := -std=c++17 $(WARN) -fopenmp -Isrc $(CHOLMOD_CFLAGS) \
             $(patsubst -I%,-isystem %,$(shell pkg-config --cflags $(PKGS) 2>/dev/null))
# OSMesa gives its headers only: the renderer loads the library when it first renders (src/render/gl_api.hpp).
LIBS     := $(filter-out -lOSMesa,$(shell pkg-config --libs $(PKGS) 2>/dev/null)) $(CHOLMOD_LIBS) -fopenmp -lpthread -ldl

RELEASE_FLAGS := -O2 -DNDEBUG -DEIGEN_NO_DEBUG
ASAN_FLAGS    := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined

LIB_SRC   := $(shell find src -name '*.cpp' ! -path 'src/app/main.cpp' | sort)
MAIN_SRC  := src/app/main.cpp
TEST_SRC  := $(shell find tests -name '*.cpp' 2>/dev/null | sort)
TEST_FLAGS := -Itests
BENCH_SRC := $(shell find tools/bench -name '*.cpp' 2>/dev/null | sort)

obj = $(patsubst %.cpp,build/$(1)/%.o,$(2))

# The sub-makes of check, demo, slowcheck, report, bench and fuzz compile on every core unless the caller chose a
# job count (`make -jN check`; `-j1` for a serial build). GNU make 4.3 shows a command-line -j in MAKEFLAGS only
# to recipes, hence the recipe-time test.
NPROC    := $(shell nproc 2>/dev/null || echo 2)
PARALLEL  = $(if $(filter -j%,$(MAKEFLAGS)),,-j$(NPROC))

.PHONY: all deps check check-release check-asan demo bench clean slowcheck fuzz report

all: bin/arcsim

deps:
	@bash dependencies/install.sh

ifneq ($(DEPS_OK),yes)
ifeq ($(filter deps clean,$(MAKECMDGOALS)),)
$(info Missing build dependencies: run `bash dependencies/install.sh` (as root), or `make check` / `make demo` which run it.)
endif
endif

build/release/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(BASEFLAGS) $(RELEASE_FLAGS) -MMD -MP -c $< -o $@

build/asan/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(BASEFLAGS) $(ASAN_FLAGS) -MMD -MP -c $< -o $@

# Tests and benchmarks may also include test support headers (tests/support/).
build/release/tests/%.o: tests/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(BASEFLAGS) $(TEST_FLAGS) $(RELEASE_FLAGS) -MMD -MP -c $< -o $@

build/asan/tests/%.o: tests/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(BASEFLAGS) $(TEST_FLAGS) $(ASAN_FLAGS) -MMD -MP -c $< -o $@

build/release/tools/%.o: tools/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(BASEFLAGS) $(TEST_FLAGS) $(RELEASE_FLAGS) -MMD -MP -c $< -o $@

bin/arcsim: $(call obj,release,$(LIB_SRC) $(MAIN_SRC))
	@mkdir -p bin
	$(CXX) -o $@ $^ $(LIBS)

bin/arcsim-tests: $(call obj,release,$(LIB_SRC) $(TEST_SRC))
	@mkdir -p bin
	$(CXX) -o $@ $^ $(LIBS) -lgtest -lgtest_main

bin/arcsim-tests-asan: $(call obj,asan,$(LIB_SRC) $(TEST_SRC))
	@mkdir -p bin
	$(CXX) -fsanitize=address,undefined -o $@ $^ $(LIBS) -lgtest -lgtest_main

bin/arcsim-asan: $(call obj,asan,$(LIB_SRC) $(MAIN_SRC))
	@mkdir -p bin
	$(CXX) -fsanitize=address,undefined -o $@ $^ $(LIBS)

SUPPORT_SRC := $(shell find tests/support -name '*.cpp' 2>/dev/null | sort)

bin/arcsim-bench: $(call obj,release,$(LIB_SRC) $(BENCH_SRC) $(SUPPORT_SRC))
	@mkdir -p bin
	$(CXX) -o $@ $^ $(LIBS) -lbenchmark -lpthread

# Tests find the binaries and the ARCSim example scenes through these variables.
TEST_ENV := ARCSIM_BIN=$(CURDIR)/bin/arcsim ARCSIM_SHARED=$(abspath $(CURDIR)/../shared)

check: deps
	@$(MAKE) --no-print-directory $(PARALLEL) check-release check-asan

# Tests named *SlowCheck* (minutes-long runs of whole ARCSim scenes) run in `make slowcheck` only.
check-release: bin/arcsim bin/arcsim-tests
	$(TEST_ENV) OMP_NUM_THREADS=2 ./bin/arcsim-tests --gtest_brief=1 --gtest_filter='-*SlowCheck*'

slowcheck: deps
	@$(MAKE) --no-print-directory $(PARALLEL) bin/arcsim bin/arcsim-tests
	$(TEST_ENV) OMP_NUM_THREADS=2 ./bin/arcsim-tests --gtest_filter='*SlowCheck*'

# Sanitizer build: the whole suite except tests marked Slow (they run above, optimised).
check-asan: bin/arcsim-asan bin/arcsim-tests-asan
	$(TEST_ENV) ARCSIM_BIN=$(CURDIR)/bin/arcsim-asan ARCSIM_SANITIZED=1 OMP_NUM_THREADS=2 \
	  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ./bin/arcsim-tests-asan --gtest_brief=1 --gtest_filter='-*Slow*'

# libFuzzer targets (fuzz/): the OBJ reader, the scene parser and the state-file reader, built with clang under
# AddressSanitizer + UndefinedBehaviorSanitizer. `make fuzz` runs each for FUZZ_SECONDS (CI: 60 s; the long runs
# reported in docs/stability.md: FUZZ_SECONDS=3600) from a seed corpus of conf/, meshes/, fuzz/state_scene/ and,
# where present, ARCSim's scenes and meshes. A finding stops make with the input saved under build/fuzz/findings/.
FUZZ_CXX      ?= clang++
FUZZ_SECONDS  ?= 60
FUZZ_FLAGS    := -std=c++17 -O1 -g -fno-omit-frame-pointer -fopenmp -Isrc $(CHOLMOD_CFLAGS) \
                 $(patsubst -I%,-isystem %,$(shell pkg-config --cflags $(PKGS) 2>/dev/null)) \
                 -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
FUZZ_TARGETS  := obj_reader scene_parser state_reader
ARCSIM_SCENES := $(abspath $(CURDIR)/../shared/arcsim-0.3-scenes)

build/fuzz/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(FUZZ_CXX) $(FUZZ_FLAGS) -MMD -MP -c $< -o $@

bin/fuzz-%: build/fuzz/fuzz/%_fuzzer.o $(call obj,fuzz,$(LIB_SRC))
	@mkdir -p bin
	$(FUZZ_CXX) -fsanitize=fuzzer,address,undefined -fopenmp -o $@ $^ $(filter-out -fopenmp,$(LIBS))

# Seeds: small files only (libFuzzer mutates up to the largest seed's length).
build/fuzz/seeds.stamp: bin/arcsim $(wildcard conf/*.json meshes/*.obj fuzz/state_scene/*)
	rm -rf build/fuzz/seeds && mkdir -p build/fuzz/seeds/obj_reader build/fuzz/seeds/scene_parser build/fuzz/seeds/state_reader
	find meshes fuzz/state_scene $(wildcard $(ARCSIM_SCENES)/meshes) -name '*.obj' -size -64k -exec cp {} build/fuzz/seeds/obj_reader/ \;
	find conf $(wildcard $(ARCSIM_SCENES)/conf $(ARCSIM_SCENES)/materials) fuzz/state_scene -name '*.json' -size -64k \
	  -exec sh -c 'cp "$$1" "build/fuzz/seeds/scene_parser/$$(echo "$$1" | tr / _)"' _ {} \;
	rm -rf build/fuzz/state_run && ./bin/arcsim simulate fuzz/state_scene/scene.json build/fuzz/state_run > /dev/null 2>&1
	cp build/fuzz/state_run/*.state build/fuzz/seeds/state_reader/
	touch $@

fuzz: deps
	@$(MAKE) --no-print-directory $(PARALLEL) $(addprefix bin/fuzz-,$(FUZZ_TARGETS)) build/fuzz/seeds.stamp
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p build/fuzz/corpus/$$t build/fuzz/findings/$$t; \
	  echo "fuzz: $$t for $(FUZZ_SECONDS) s"; \
	  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ./bin/fuzz-$$t build/fuzz/corpus/$$t \
	    build/fuzz/seeds/$$t -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 \
	    -artifact_prefix=build/fuzz/findings/$$t/ 2> build/fuzz/$$t.log \
	    || { tail -n 60 build/fuzz/$$t.log; echo "fuzz: $$t found a failing input (build/fuzz/findings/$$t/)"; exit 1; }; \
	  grep -E '^stat::(number_of_executed_units|new_units_added|peak_rss_mb)' build/fuzz/$$t.log | tr '\n' ' '; echo; \
	done

demo: deps
	@$(MAKE) --no-print-directory $(PARALLEL) bin/arcsim
	./bin/arcsim simulate conf/demo.json out/demo
	./bin/arcsim replay out/demo out/demo/png
	@echo "demo: frames in out/demo/, rendered PNGs in out/demo/png/"

# The paper's scenes, each run to its end and checked frame by frame, with a Table 1 of ours, contact sheets
# (docs/img/) and the plots of speed against error, written into docs/benchmarks.md (tools/report.py,
# tools/speed_vs_error.py). ARCSIM=/path/to/arcsim adds ARCSim 0.3.1's fracture scenes side by side.
report: deps
	@$(MAKE) --no-print-directory $(PARALLEL) bin/arcsim
	./tools/report.py --update-benchmarks docs/benchmarks.md $(if $(ARCSIM),--arcsim $(ARCSIM))
	./tools/speed_vs_error.py --arcsim-bin bin/arcsim --out docs/img --markdown docs/speed-vs-error.md
	./tools/fig10.py --seeds 4 --markdown docs/fig10.md --plot docs/img/fig10.png

bench: deps
	@$(MAKE) --no-print-directory $(PARALLEL) bin/arcsim-bench
	OMP_NUM_THREADS=2 ./bin/arcsim-bench

clean:
	rm -rf build bin

-include $(shell find build -name '*.d' 2>/dev/null)
