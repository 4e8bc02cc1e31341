# packbed: `make` builds (release) and runs the default pipeline;
# `make test` runs formatting, lints, docs and every test.
CARGO ?= cargo
OUT ?= out
# Where cargo puts the release build (CARGO_TARGET_DIR if set).
BIN := $(or $(CARGO_TARGET_DIR),target)/release

PREFIX ?= /usr/local
TOOLS := mkpellet pack settle-check voidprof compare bedexport paper-report

.PHONY: all build install pipeline test fuzz test-slurm test-openfoam lint doc bench t14 t14-sensitivity clean paper paper-validation paper-loading paper-cor paper-friction paper-report paper-park stepper-study stepper-study-halving stepper-study-report

all: pipeline

build:
	$(CARGO) build --release --workspace --bins

# The seven tools into $(PREFIX)/bin (release build; e.g. make install PREFIX=$$HOME/.local).
install: build
	mkdir -p $(DESTDIR)$(PREFIX)/bin
	for t in $(TOOLS); do install -m 755 $(BIN)/$$t $(DESTDIR)$(PREFIX)/bin/$$t || exit 1; done

pipeline: build
	@$(MAKE) --no-print-directory -f pipelines/default.mk BIN=$(BIN) OUT=$(OUT)

lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

doc:
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps

test: lint doc
	$(CARGO) build --workspace --bins
	$(CARGO) test --workspace

# The readers' property tests (damaged, cut and hostile pellet, packing, trajectory, poses CSV,
# STL, OBJ and case files) with FUZZ_CASES cases each instead of the few hundred `make test`
# runs: a soak of several minutes, not part of `make test`.
FUZZ_CASES ?= 20000
fuzz:
	PROPTEST_CASES=$(FUZZ_CASES) $(CARGO) test -p pellet_io --test fuzz_framed --test fuzz_trajectory --test fuzz_text
	PROPTEST_CASES=$(FUZZ_CASES) $(CARGO) test -p pellet_pack --test fuzz_case_file

# The pipelines on a real one-node Slurm started for the test (Debian's
# slurm-wlm and munge), against the same runs made locally (tests/slurm/test.sh;
# about 2 min). Fails when Slurm cannot start.
test-slurm: build
	sh tests/slurm/test.sh $(BIN)

# bedexport --openfoam meshed for real: a 20-sphere, a 20-cylinder and a 20-ring bed through
# surfaceCheck (pellets.stl closed, not self-intersecting), blockMesh, surfaceFeatureExtract,
# snappyHexMesh and checkMesh, then simpleFoam on the sphere bed, its pressure drop against
# Ergun's (tests/openfoam/test.sh; about 14 min on one core; BEDS="spheres rings" picks beds;
# installs Debian's openfoam package when missing, fails when it cannot).
test-openfoam: build
	sh tests/openfoam/test.sh $(BIN)

# Speed figures (not tests): the engine pouring spheres, cylinders and rings
# with pack's contact model (PELLET_BENCH_CASES / _SIM_SECONDS / _WALL_SECONDS /
# _MODE tune it, see crates/pellet_sim/benches/pack_beds.rs), voidprof, and
# bedexport's stages on a 600-sphere bed, the two steppers side by side (with
# LIGGGHTS on the 690-sphere bed), and the velocity-level stepper beside rapier on
# its 256-ring and 620-cylinder beds, how it scales to 5000 spheres and 2000
# cylinders, and pack on one thread and two
# (pipelines/bench-threads.sh). Each stage's figures are shown and kept in $(BENCH_OUT)/STAGE.txt;
# at the end pipelines/benchmarks-md.sh writes them, with the machine and the
# build, to BENCHMARKS.md (replaced whole, only by a run that got to the end).
BENCH_OUT ?= $(OUT)/bench
bench: export PELLET_BENCH_MODE ?= recommended
bench: export PELLET_BENCH_EXACT_ROWS ?= 16
bench: export PELLET_BENCH_EXACT_FALLBACK ?= 64
# $(call bench_stage,NAME,COMMAND): COMMAND's stdout on the terminal and in
# $(BENCH_OUT)/NAME.txt; fails when COMMAND fails (which a pipe alone would hide).
bench_stage = echo '== $(1) (figures kept in $(BENCH_OUT)/$(1).txt)'; rm -f $(BENCH_OUT)/$(1).failed; \
  { $(2) || echo $$? >$(BENCH_OUT)/$(1).failed; } | tee $(BENCH_OUT)/$(1).txt; \
  if [ -e $(BENCH_OUT)/$(1).failed ]; then exit "$$(cat $(BENCH_OUT)/$(1).failed)"; fi
bench:
	@mkdir -p $(BENCH_OUT) && date -u '+%Y-%m-%d %H:%M UTC' >$(BENCH_OUT)/started
	@$(call bench_stage,pack_beds,$(CARGO) bench -p pellet_sim --bench pack_beds)
	@$(call bench_stage,voidprof,$(CARGO) run --release -p pellet_analysis --example bench_voidprof)
	@$(call bench_stage,export,$(CARGO) run --release -p pellet_export --example bench_export)
	$(CARGO) build --release --workspace --bins
	@$(call bench_stage,steppers,bash pipelines/bench-steppers.sh $(BIN))
	@$(call bench_stage,peers,STEPPERS=velocity bash pipelines/bench-steppers.sh $(BIN) "ring256 cyl620")
	@$(call bench_stage,scaling,STEPPERS=velocity bash pipelines/bench-steppers.sh $(BIN) "sph690 sph5000 cyl620 cyl2000")
	@$(call bench_stage,threads,bash pipelines/bench-threads.sh $(BIN))
	sh pipelines/benchmarks-md.sh $(BENCH_OUT) BENCHMARKS.md

# T14 (not a test: minutes of one core): 1000 spheres in a 100 mm
# tube, batch loading, scored against the correlations (pipelines/t14.mk).
t14: build
	$(MAKE) --no-print-directory -f pipelines/t14.mk BIN=$(BIN) OUT=$(OUT)/t14

# T14's sensitivity of porosity to εp, μ and the friction rule
# (pipelines/t14-sensitivity.mk): ten 1000-sphere beds, about 5 min each.
t14-sensitivity: build
	$(MAKE) --no-print-directory -f pipelines/t14-sensitivity.mk BIN=$(BIN) OUT=$(OUT)/t14-sensitivity

# The paper's study (pipelines/paper.mk, README "The paper's study: make paper"):
# beds under $(PAPER_OUT), the report in $(PAPER_DOCS). REPEATS=k runs seeds
# 1..k only. The report is written from whatever beds exist, also when some
# failed (the exit status is still the beds'). `+` marks the recipes as
# recursive make, so `make -j2 paper` shares its job slots with them.
# Every pipeline's beds run pack on THREADS threads each (default 1, so
# `make -j2 paper` keeps two cores busy, not four); THREADS=k for fewer, bigger beds.
PAPER_OUT ?= $(OUT)/paper
PAPER_DOCS ?= docs/validation
REPEATS ?=
PAPER = $(MAKE) --no-print-directory -f pipelines/paper.mk BIN=$(BIN) OUT=$(PAPER_OUT) DOCS=$(PAPER_DOCS) REPEATS=$(REPEATS)

paper paper-validation paper-loading paper-cor paper-friction: build
	+$(PAPER) $(if $(filter paper,$@),all,$(@:paper-%=%)) || status=$$?; $(PAPER) report && exit $${status:-0}

paper-report: build
	+$(PAPER) report

# Park the paper beds' partial runs in $(PAPER_DOCS)/parked (stop them first):
# small copies, to commit, that the next `make paper…` anywhere resumes from.
paper-park: build
	+$(PAPER) park

# The steppers' equivalence study (pipelines/stepper-study.mk, docs/validation/reproducing.md
# "The steppers' equivalence study"): the paper's validation tubes and the 690-sphere batch bed
# packed with `pack --stepper velocity`, against the force-level beds recorded for the same
# cases. Beds under $(STEPPER_STUDY_OUT), records in $(PAPER_DOCS)/stepper-study, the report in
# $(PAPER_DOCS)/stepper-study.md, written also when some beds failed. Resumable: a bed with a
# record is not run again. A subset: TUBES="val-sphere-D41 ..." (the paper's validation
# configurations), SEEDS=k (seeds 1..k of each, default 6), SPHERE690_SEEDS=k (default 20;
# empty: none). About 4 h of one core in all; `make -j2 stepper-study` runs two beds at once.
STEPPER_STUDY_OUT ?= $(OUT)/stepper-study
STEPPER_STUDY = $(MAKE) --no-print-directory -f pipelines/stepper-study.mk BIN=$(BIN) OUT=$(STEPPER_STUDY_OUT) DOCS=$(PAPER_DOCS)

stepper-study: build
	+$(STEPPER_STUDY) beds || status=$$?; $(STEPPER_STUDY) report && exit $${status:-0}

# Where the two steppers differ, the step-halving arms decide which has not converged: the
# study's failing configurations packed by the velocity-level stepper at half its step and by
# the force-level one at a quarter of its substep (pipelines/stepper-study.mk, ARM), records
# in $(PAPER_DOCS)/stepper-study/{velocity-half,force-quarter}, then the report. About 1.5 h
# of one core for 6 seeds of the default configurations (TUBES, SEEDS as above).
stepper-study-halving: build
	+$(STEPPER_STUDY) ARM=velocity-half beds || status=$$?; \
	  $(STEPPER_STUDY) ARM=force-quarter beds || status=$$?; $(STEPPER_STUDY) report && exit $${status:-0}

stepper-study-report:
	$(STEPPER_STUDY) report

clean:
	rm -rf $(OUT)
