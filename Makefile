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
LIBS     := $(shell pkg-config --libs $(PKGS) 2>/dev/null) $(CHOLMOD_LIBS) -fopenmp -lpthread

RELEASE_FLAGS := -O2 -DNDEBUG -DEIGEN_NO_DEBUG
ASAN_FLAGS    := -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined

LIB_SRC   := $(shell find src -name '*.cpp' ! -path 'src/app/main.cpp' | sort)
MAIN_SRC  := src/app/main.cpp
TEST_SRC  := $(shell find tests -name '*.cpp' 2>/dev/null | sort)
TEST_FLAGS := -Itests
BENCH_SRC := $(shell find tools/bench -name '*.cpp' 2>/dev/null | sort)

obj = $(patsubst %.cpp,build/$(1)/%.o,$(2))

.PHONY: all deps check check-release check-asan demo bench clean slowcheck

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
	@$(MAKE) --no-print-directory check-release check-asan

# Tests named *SlowCheck* (minutes-long runs of whole ARCSim scenes) run in `make slowcheck` only.
check-release: bin/arcsim bin/arcsim-tests
	$(TEST_ENV) OMP_NUM_THREADS=2 ./bin/arcsim-tests --gtest_brief=1 --gtest_filter='-*SlowCheck*'

slowcheck: deps
	@$(MAKE) --no-print-directory bin/arcsim bin/arcsim-tests
	$(TEST_ENV) OMP_NUM_THREADS=2 ./bin/arcsim-tests --gtest_filter='*SlowCheck*'

# Sanitizer build: the whole suite except tests marked Slow (they run above, optimised).
check-asan: bin/arcsim-asan bin/arcsim-tests-asan
	$(TEST_ENV) ARCSIM_BIN=$(CURDIR)/bin/arcsim-asan ARCSIM_SANITIZED=1 OMP_NUM_THREADS=2 \
	  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ./bin/arcsim-tests-asan --gtest_brief=1 --gtest_filter='-*Slow*'

demo: deps
	@$(MAKE) --no-print-directory bin/arcsim
	./bin/arcsim simulate conf/demo.json out/demo
	./bin/arcsim replay out/demo out/demo/png
	@echo "demo: frames in out/demo/, rendered PNGs in out/demo/png/"

bench: deps
	@$(MAKE) --no-print-directory bin/arcsim-bench
	OMP_NUM_THREADS=2 ./bin/arcsim-bench

clean:
	rm -rf build bin

-include $(shell find build -name '*.d' 2>/dev/null)
