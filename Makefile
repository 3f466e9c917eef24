# ballast — build, test, validate, benchmark.
#
#   make validate     build, run the default tier of the catalogue, gate, sweeps, report
#   make gate         the pre-commit gate: the quick tier gated, no sweeps or stability (< 30 s)
#   make sweep        the declared error-against-cost sweeps alone (needs the default runs)
#   make test         C unit tests (Check), symbol-prefix check, harness tests (pytest; installs
#                     python3-vtk9 for the VTK reader test when it can)
#   make test-sanitize  C unit tests under AddressSanitizer + UndefinedBehaviorSanitizer
#   make test-valgrind  one case under valgrind memcheck
#   make test-slurm   harness export through a one-node Slurm on localhost (installs Slurm, MUNGE)
#   make bench        dense-packing benchmark (median and spread of 5 repeats); the biaxial test
#                     and the polydisperse pile against the race's dense scene, in one run
#   make bench-peer   ballast against LAMMPS on the same physics (cross-check, then the race)
#   make validate-peers  the catalogue through LAMMPS too, gated by the same references (reports/peers/)
#   make test-peers   the engine adapters' tests with LAMMPS (installs it)
#   make bench-flat   the 1 000 000- against the 20 000-disc rate, alternating in one process
#   make bench-threads  2 OpenMP threads against 1 on the settled packing (20 000, 320 000 discs)
#   make bench-cost   the cost model: per phase and particle-step, counts, bytes, cycles; the machine
#   make clean

# ---- settings -------------------------------------------------------------
CC       ?= cc
PYTHON   ?= /usr/bin/python3
TIER     ?= standard
JOBS     ?= $(shell nproc 2>/dev/null || echo 2)
OPT      ?= -O2
WERROR   ?=
CFLAGS_BASE := -std=c11 -Wall -Wextra -Wpedantic -ffp-contract=off -fopenmp \
               -D_POSIX_C_SOURCE=200809L $(WERROR)
CFLAGS   ?= $(OPT) -g
ALL_CFLAGS = $(CFLAGS_BASE) $(CFLAGS) -DBAL_BUILD_FLAGS='"$(CC) $(CFLAGS_BASE) $(CFLAGS)"'
LDLIBS   := $(shell pkg-config --libs gsl 2>/dev/null || echo -lgsl -lgslcblas) -lm
CHECK_LIBS = $(shell pkg-config --libs check 2>/dev/null)
SAN      := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

BUILD    := build
LIB_SRC  := $(filter-out core/main.c,$(wildcard core/*.c))
LIB_OBJ  := $(LIB_SRC:core/%.c=$(BUILD)/%.o)
TEST_SRC := $(wildcard core/tests/check_*.c)
BENCH_SRC := core/bench/bench.c

.PHONY: all deps vtk-deps test test-c test-prefix test-py test-sanitize test-browser validate gate bench bench-scaling \
        bench-peer bench-modules bench-modules-count bench-scaling-count bench-flat bench-threads bench-cost bench-piles-poly \
        clean keys sweep \
        test-valgrind test-slurm validate-peers test-peers

all: deps bin/ballast

# Install missing Debian packages (quiet and quick when all are present).
deps:
	@sh .ci/install-deps

# ---- library and command --------------------------------------------------
# deps first, even under make -j on a fresh machine (GSL's headers come from it).
$(BUILD)/%.o: core/%.c | $(BUILD) deps
	$(CC) $(ALL_CFLAGS) $(FILE_CFLAGS) -MMD -MP -c $< -o $@

# The contact loops at -O3: 3 % more particle-steps/s on the dense race scene,
# the same bits in every output (docs/benchmarks.md, speed round two): the
# disc-disc loop, its thread plan (which runs at every rebuild) and the
# disc-wall loop, one file each since issue 30; the rest of the core stays at
# $(OPT).
$(BUILD)/pair_loop.o $(BUILD)/threads.o $(BUILD)/wall_loop.o: FILE_CFLAGS := -O3

$(BUILD)/libballast.a: $(LIB_OBJ)
	ar rcs $@ $^

bin/ballast: $(BUILD)/main.o $(BUILD)/libballast.a | bin
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD) bin $(BUILD)/san:
	mkdir -p $@

# ---- tests ----------------------------------------------------------------
$(BUILD)/check_ballast: $(TEST_SRC) $(BUILD)/libballast.a core/tests/check_main.h
	$(CC) $(ALL_CFLAGS) -Icore -o $@ $(TEST_SRC) $(BUILD)/libballast.a $(CHECK_LIBS) $(LDLIBS)

test: deps bin/ballast test-prefix test-c test-py

test-c: $(BUILD)/check_ballast
	cd core/tests && CK_FORK=yes ../../$(BUILD)/check_ballast

# Every symbol the library exports starts with bal_ (STYLE practice 7).
test-prefix: $(LIB_OBJ)
	@bad=$$(nm -g --defined-only $(LIB_OBJ) | awk 'NF==3 && $$3 !~ /^bal_/ {print $$3}'); \
	if [ -n "$$bad" ]; then echo "symbols without the bal_ prefix: $$bad"; exit 1; fi; \
	echo "prefix check: every exported symbol starts with bal_"

test-py: bin/ballast vtk-deps
	$(PYTHON) -m pytest -q harness/tests

# Debian's VTK for Python, the reader harness/tests/test_vtk.py opens a run's VTK snapshots
# with; where it cannot be installed (no root, no network) make test goes on and that test
# skips, saying why.
vtk-deps:
	@sh .ci/install-vtk-deps || echo "vtk-deps: python3-vtk9 could not be installed; harness/tests/test_vtk.py will skip"

# Sanitized build of the library and the C tests, in its own directory.
SAN_OBJ := $(LIB_SRC:core/%.c=$(BUILD)/san/%.o)
$(BUILD)/san/%.o: core/%.c | $(BUILD)/san
	$(CC) $(CFLAGS_BASE) -O1 -g $(SAN) -MMD -MP -c $< -o $@

$(BUILD)/san/check_ballast: $(TEST_SRC) $(SAN_OBJ) core/tests/check_main.h
	$(CC) $(CFLAGS_BASE) -O1 -g $(SAN) -Icore -o $@ $(TEST_SRC) $(SAN_OBJ) $(CHECK_LIBS) $(LDLIBS)

test-sanitize: deps $(BUILD)/san/check_ballast
	cd core/tests && CK_FORK=no ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ../../$(BUILD)/san/check_ballast

# Cases under valgrind's memcheck: an independent look at the memory the
# sanitizers also watch, on the real command line (scene file, outputs, run.json):
# two discs (all pairs, damping), a pile (cell grid, ramp, stop rule) and the exact solver.
test-valgrind: bin/ballast
	@command -v valgrind >/dev/null || { echo "test-valgrind: valgrind is not installed (sh .ci/install-deps)"; exit 1; }
	rm -rf $(BUILD)/valgrind && mkdir -p $(BUILD)/valgrind
	valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,possible \
	  bin/ballast run cases/two_discs/two_discs.scene --out $(BUILD)/valgrind/two_discs \
	  --set settings.alpha=10 --set settings.beta=0.005
	valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,possible \
	  bin/ballast run cases/piles/pile30_smooth.scene --out $(BUILD)/valgrind/pile \
	  --set stage.ramp.cycles=500 --set stage.relax.cycles=500
	valgrind -q --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,possible \
	  bin/ballast exact cases/piles/pile30_smooth.scene --out $(BUILD)/valgrind/exact
	@echo "test-valgrind: two_discs (damped), a pile (grid, stages) and the exact solver clean under memcheck"

# The Slurm path of `harness export` for real (docs/ensembles.md): installs slurm-wlm and munge
# (the optional group of .ci/install-deps), starts munged, slurmctld and slurmd on localhost
# with a minimal config in a temporary folder, runs the test ensemble as a job array, gathers
# it, compares it with a local run byte for byte, and always stops the daemons it started.
# Not in make test or .ci/run (about 20 s once installed; needs root).
test-slurm: bin/ballast
	@sh .ci/install-deps slurm
	bash harness/tests/slurm/run

# The HTML report of the last validate in a real browser (headless chromium through
# chromedriver: images decode, links resolve, no console error, size; reports/browser.png).
test-browser:
	sh .ci/install-browser-deps
	$(PYTHON) -m pytest -q harness/tests/test_browser.py

# ---- validation -----------------------------------------------------------
# RESUME=1 (or yes) keeps the runs an interrupted validate finished (--resume); RESUME=0, no
# or empty runs everything; any other value is refused (RESUME=maybe, true, off: a switch
# must not read "0" as "on", as a bare $(if $(RESUME),...) would).  CASES="a b" validates
# those cases only and updates their part of the report.
RESUME_FLAG := $(if $(filter 1 yes,$(RESUME)),--resume)
ifneq ($(filter validate,$(MAKECMDGOALS)),)
ifneq ($(or $(filter-out 0 1 no yes,$(RESUME)),$(word 2,$(RESUME))),)
$(error RESUME=$(RESUME): give RESUME=1 or yes to resume, RESUME=0 or no (or nothing) to run everything)
endif
endif
validate: all
	$(PYTHON) -m harness validate --tier $(TIER) -j $(JOBS) $(RESUME_FLAG) $(CASES)

# The pre-commit gate for a change to the core (issue 32, item 4): the quick tier, gated, without
# the sweeps, the stability limits and the extreme probes.  Every law path runs in it: the
# incremental law (two_discs, nine_discs_*), the power law and its dashpot (collisions, piles),
# the two-contacts-at-a-time loop with sliding (coulomb), rolling Models 1 and 2 (rolling_tester),
# the wall controllers and the exact solver.  Its time is measured in docs/benchmarks.md.
gate: all
	$(PYTHON) -m harness validate --tier quick --no-sweeps --no-stability -j $(JOBS)

# Error against cost: every [sweep] of the tier's cases -> reports/sweeps/<case>/cost.tsv
# (validate runs them too, between the gate and the report; `harness report` draws them).
sweep: all
	$(PYTHON) -m harness cost --tier $(TIER) -j $(JOBS)

# The agreement matrix (issue 34, docs/engines.md): every case of TIER through ballast and LAMMPS,
# each check evaluated on both engines' runs, side by side with their costs, in reports/peers/
# (linked from the report).  LAMMPS is installed with apt-get when `lmp` is missing.  Not part of
# validate or test.  RESUME=1 keeps the LAMMPS runs already made (ballast's identical runs are
# always kept); REALISATIONS=N runs N realisations of each [ensemble] in both engines (default
# 10; 0 for all, the full tier's); CASES="a b" those cases only.
REALISATIONS ?= 10
validate-peers: all
	$(PYTHON) -m harness.engines.matrix --tier $(TIER) -j $(JOBS) --realisations $(REALISATIONS) \
	  $(RESUME_FLAG) $(CASES)

test-peers: all
	@command -v lmp >/dev/null || $(PYTHON) -c "from harness.engines.lammps import lammps_problem; \
	  import sys; p = lammps_problem(); sys.exit('test-peers: ' + p if p else 0)"
	$(PYTHON) -m pytest -q harness/tests/test_engines_lammps.py harness/tests/test_engines.py \
	  harness/tests/test_peer.py harness/tests/test_peer_rolling.py

# ---- benchmark ------------------------------------------------------------
$(BUILD)/bench: $(BENCH_SRC) $(BUILD)/libballast.a
	$(CC) $(ALL_CFLAGS) -Icore -o $@ $(BENCH_SRC) $(BUILD)/libballast.a $(LDLIBS)

bench: deps $(BUILD)/bench
	$(BUILD)/bench cases/bench/dense.scene
	$(BUILD)/bench --settling cases/bench/dense.scene 20000
	$(BUILD)/bench --pile cases/piles/pile30_bumpy.scene
	$(BUILD)/bench --workload cases/bench/dense.scene cases/biaxial/biaxial.scene \
	  cases/piles_poly/pile_poly.scene

# Realisations per hour per core of the polydisperse L0 = 100 pile at r_d = 1/30
# (issue 22): 20 seeds one after the other, CPU time per realisation, cycles to rest,
# and what a series row every cycle would cost (docs/benchmarks.md).
bench-piles-poly: all
	$(PYTHON) core/bench/piles_poly.py bin/ballast cases/piles_poly/pile_poly.scene 20 --every-cycle 3

# What each optional module costs: one simulation per configuration from the same
# settled packing, then the all-off configuration in a build without the modules
# (-DBAL_BARE), alternately, so the cost of a switched-off module is measured.
BARE_OBJ := $(LIB_SRC:core/%.c=$(BUILD)/bare/%.o)
$(BUILD)/bare/%.o: core/%.c $(wildcard core/*.h) | $(BUILD)
	@mkdir -p $(BUILD)/bare
	$(CC) $(ALL_CFLAGS) $(FILE_CFLAGS) -DBAL_BARE -c -o $@ $<
$(BUILD)/bare/pair_loop.o $(BUILD)/bare/threads.o $(BUILD)/bare/wall_loop.o: FILE_CFLAGS := -O3
$(BUILD)/bench-bare: $(BENCH_SRC) $(BARE_OBJ)
	$(CC) $(ALL_CFLAGS) -DBAL_BARE -Icore -o $@ $(BENCH_SRC) $(BARE_OBJ) $(LDLIBS)

bench-modules: deps $(BUILD)/bench $(BUILD)/bench-bare
	$(BUILD)/bench --modules cases/bench/dense.scene 20000
	$(MAKE) --no-print-directory bench-modules-count

# The all-off scene in the normal and the bare build, compared by what the machine's
# load does not change (about 4 minutes; wall-clock repeats of one binary spread by
# +-25 % on a shared VM, and it has no hardware counters):
# 1. instructions and simulated cache misses per particle-step of the timed cycles
#    alone, counted by callgrind (the packing is read from a file, so only scene load
#    and creation run uninstrumented under valgrind: COUNT_N discs keeps that short);
# 2. wall clock pinned to one core: WALL_PAIRS alternating pairs of processes, each
#    WALL_RUNS runs of WALL_STEPS cycles.  The settled packings are cached in $(BUILD).
COUNT_N     ?= 5000
COUNT_STEPS ?= 100
WALL_N      ?= 20000
WALL_PAIRS  ?= 15
WALL_STEPS  ?= 250
WALL_RUNS   ?= 5
WALL_CPU    ?= 1
# Fixed simulated caches (this VM's L1s; the 512 MB L3 it reports is not a real one), so
# the counts do not depend on the machine.
CALLGRIND_CACHES := valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no \
                    --cache-sim=yes --I1=32768,8,64 --D1=49152,12,64
CALLGRIND   := $(CALLGRIND_CACHES) --LL=8388608,16,64
STEP        := --modules-step cases/bench/dense.scene

$(BUILD)/modules-%.pack: $(BUILD)/bench cases/bench/dense.scene
	$(BUILD)/bench --modules-pack cases/bench/dense.scene $* $@

bench-modules-count: deps $(BUILD)/bench $(BUILD)/bench-bare $(BUILD)/modules-$(COUNT_N).pack \
                     $(BUILD)/modules-$(WALL_N).pack
	for b in bench bench-bare; do \
	  $(CALLGRIND) --callgrind-out-file=$(BUILD)/$$b.callgrind $(BUILD)/$$b $(STEP) \
	    $(BUILD)/modules-$(COUNT_N).pack $(COUNT_STEPS) 1 >$(BUILD)/$$b.count \
	    2>$(BUILD)/$$b.callgrind.log || exit 1; done
	rm -f $(BUILD)/modules-wall.txt; for k in $$(seq $(WALL_PAIRS)); do for b in bench bench-bare; do \
	  taskset -c $(WALL_CPU) $(BUILD)/$$b $(STEP) $(BUILD)/modules-$(WALL_N).pack $(WALL_STEPS) \
	    $(WALL_RUNS) >>$(BUILD)/modules-wall.txt || exit 1; done; done
	@for b in bench bench-bare; do echo "# $$b: Ir per particle-step of the timed cycles, by function"; \
	  callgrind_annotate --inclusive=no --show=Ir $(BUILD)/$$b.callgrind 2>/dev/null | grep -E ' \[.*\]$$' | \
	    head -7 | awk '{ gsub(",", "", $$1); printf "%10.2f  %s\n", $$1 / ($(COUNT_N) * $(COUNT_STEPS)), $$(NF - 1) }'; \
	done
	$(BUILD)/bench --modules-summary $(BUILD)/bench.callgrind $(BUILD)/bench.count \
	  $(BUILD)/bench-bare.callgrind $(BUILD)/bench-bare.count $(BUILD)/modules-wall.txt

# ballast against LAMMPS (installed with apt-get when missing; not a build or test
# dependency): a cross-check of the same physics, then 5 alternating repeats per
# scene (harness/peer/race.py, run as a module: python3 -m harness.peer.race).
bench-peer: deps bin/ballast
	$(PYTHON) -m harness.peer.race --ballast bin/ballast

# Particle-steps per second from 1 000 to 1 000 000 discs (about 40 minutes).
bench-scaling: deps $(BUILD)/bench
	$(BUILD)/bench cases/bench/dense.scene 1000 5000 20000 80000 320000 1000000

# The flat-scaling target judged in one process: the 20 000- and the 1 000 000-disc
# packings settled, then 15 rounds of timed runs alternating between them, so that
# this VM's drift falls on both alike (about 30 minutes, most of it settling, on every core).
bench-flat: deps $(BUILD)/bench
	$(BUILD)/bench --pair cases/bench/dense.scene 20000 1000000 15

# OpenMP: on each settled packing, timed runs alternating between 1 and 2 threads, 9
# rounds (about 10 minutes, most of it settling the 320 000 discs).  The results are
# bitwise those of one thread (make test checks it), so only the time differs.
bench-threads: deps $(BUILD)/bench
	$(BUILD)/bench --threads cases/bench/dense.scene 20000 2 9
	$(BUILD)/bench --threads cases/bench/dense.scene 320000 2 9

# Why the rate falls with N, in figures the machine's load does not change: per
# particle-step of the timed cycles of the all-off packing (read from a file),
# instructions and simulated misses of a 48 KB D1 and a 32 MB last level (this VM's
# L1d and L3), for SCALING_COUNT_N (about 15 minutes, most of it settling the packs).
SCALING_COUNT_N ?= 5000 20000 80000 320000
CALLGRIND_L3 := $(CALLGRIND_CACHES) --LL=33554432,16,64
bench-scaling-count: deps $(BUILD)/bench $(foreach n,$(SCALING_COUNT_N),$(BUILD)/modules-$(n).pack)
	@echo "N Ir D1_read_miss D1_write_miss LL_read_miss LL_write_miss (per particle-step)"
	@for n in $(SCALING_COUNT_N); do \
	  $(CALLGRIND_L3) --callgrind-out-file=$(BUILD)/scaling-$$n.callgrind $(BUILD)/bench $(STEP) \
	    $(BUILD)/modules-$$n.pack 20 1 >/dev/null 2>$(BUILD)/scaling-$$n.log || exit 1; \
	  callgrind_annotate --inclusive=no $(BUILD)/scaling-$$n.callgrind 2>/dev/null | \
	    grep 'PROGRAM TOTALS' | sed 's/([^)]*)//g; s/,//g' | \
	    awk -v n=$$n '{ ps = n * 20; printf "%d %.1f %.2f %.2f %.3f %.3f\n", n, $$1 / ps, \
	      $$5 / ps, $$6 / ps, $$8 / ps, $$9 / ps }'; \
	done

# The cost model of issue 24 (docs/benchmarks.md, "Cost model"): for the two scenes of
# bench-peer, per phase and particle-step, instructions, data accesses and simulated misses
# (callgrind, sampled windows), cycles from the phase timers of pinned runs, and what one
# core can do (clock, peak flops, triad bandwidth).  About 15 minutes on the shared VM.
$(BUILD)/cost_machine: core/bench/cost_machine.c | $(BUILD)
	$(CC) -std=c11 -O2 -fno-tree-vectorize -Wall -Wextra -D_POSIX_C_SOURCE=200809L -o $@ $< -lm

bench-cost: deps bin/ballast $(BUILD)/bench $(BUILD)/cost_machine
	$(PYTHON) core/bench/cost.py

keys: bin/ballast
	bin/ballast keys

clean:
	rm -rf $(BUILD) bin reports/runs reports/figures reports/sweeps reports/bench \
	       reports/*.json reports/*.xml reports/*.html reports/summary.md

-include $(LIB_OBJ:.o=.d) $(SAN_OBJ:.o=.d) $(BUILD)/main.d

# ---- fuzzing (issues 7 and 18) ---------------------------------------------
# Two libFuzzer targets (clang -fsanitize=fuzzer,address,undefined), sharing the
# checks of core/tests/fuzz_common.h:
#   fuzz_scene     the scene parser, --set, validate and short runs of small scenes
#                  (core/tests/fuzz_scene.c), seeded at run time with every shipped
#                  scene and core/tests/fuzz/seeds; it first replays the scenes that
#                  once failed (core/tests/fuzz/regress); 10 s an input;
#   fuzz_extremes  well-formed scenes of legal but extreme numbers built from the
#                  fuzzer's bytes (core/tests/fuzz_extremes.c); 3 s an input.
# Fails on any crash, leak, timeout, undefined behaviour or broken invariant (a
# refusal without its origin, a run that returns ok with a non-finite quantity).
# FUZZ_TIME seconds of fuzzing in all, split evenly across FUZZ_TARGETS:
# FUZZ_TIME=600 make test-fuzz runs longer, FUZZ_TARGETS=fuzz_extremes one target.
FUZZ_CC      ?= clang
FUZZ_TIME    ?= 60
FUZZ_TARGETS ?= fuzz_scene fuzz_extremes
FUZZ_SAN  := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_OBJ  := $(LIB_SRC:core/%.c=$(BUILD)/fuzz/%.o)
FUZZ_BINS := $(BUILD)/fuzz/fuzz_scene $(BUILD)/fuzz/fuzz_extremes
$(BUILD)/fuzz/%.o: core/%.c $(wildcard core/*.h)
	@mkdir -p $(BUILD)/fuzz
	$(FUZZ_CC) $(CFLAGS_BASE) -O1 -g $(FUZZ_SAN) -fsanitize=fuzzer-no-link -c $< -o $@
$(FUZZ_BINS): $(BUILD)/fuzz/%: core/tests/%.c core/tests/fuzz_common.h $(FUZZ_OBJ)
	$(FUZZ_CC) $(CFLAGS_BASE) -O1 -g $(FUZZ_SAN) -fsanitize=fuzzer -Icore -o $@ $< $(FUZZ_OBJ) \
	  $(LDLIBS)

.PHONY: test-fuzz fuzz-deps
fuzz-deps:
	@sh .ci/install-fuzz-deps
test-fuzz: fuzz-deps
	$(MAKE) -j$(JOBS) $(FUZZ_TARGETS:%=$(BUILD)/fuzz/%)
	@set -e; each=$$(( $(FUZZ_TIME) / $(words $(FUZZ_TARGETS)) )); \
	for t in $(FUZZ_TARGETS); do \
	  echo "sh core/tests/fuzz/run $(BUILD)/fuzz/$$t $$each"; \
	  sh core/tests/fuzz/run $(BUILD)/fuzz/$$t $$each; \
	done
