# The steppers' equivalence study: the paper's validation tubes and the
# 690-sphere batch bed packed with `pack --stepper velocity`, against the
# force-level (`--stepper acceleration`) beds already recorded for the same
# cases. Bed by bed, as pipelines/paper.mk: one case file per bed, then
# pack → settle-check → voidprof, and a report over whatever has finished.
# Every file is a Make target, so a re-run skips finished beds and `make -j2`
# runs two beds at once (each recipe writes only its own bed's files).
#
# A validation tube's bed is the paper's case, bit for bit (pipelines/paper/case.awk
# on $(TABLE): pellet, tube, fill height, scheme, time limit, seed), with
# `stepper = "velocity"` added and without the table's release height: the
# force-level references were poured 30 mm above the bed surface, and so are
# the beds compared with them; its force-level reference is the force-level study's
# records of the same tube in $(REFERENCE). The 690-sphere bed comes from this
# study's own table $(STUDY_TABLE), which also holds its force-level reference
# (a mean over 20 seeds, no profile) for as long as $(REFERENCE) has no records of it.
#
# A finished bed's record (summary, profile, poses, settle report, stage
# times) is copied into $(ARCHIVE), which is committed with the report. The
# record is the bed's target and has no prerequisites, so a bed finished once
# is not run again, in this checkout or any clone, and the report can be
# regenerated from the records alone. To run a bed again (a new engine, say),
# delete its record: rm $(ARCHIVE)/<id>.* $(RUNS)/<id>.*
#
#   make -f pipelines/stepper-study.mk beds     the beds
#   make -f pipelines/stepper-study.mk report   $(REPORT) from the records
#   make -f pipelines/stepper-study.mk ARM=force-quarter beds   an arm's beds (below)
#
# TUBES: the paper's validation configurations to pack (ids of $(TABLE));
# SEEDS=k packs seeds 1..k of each; SPHERE690_SEEDS=k seeds 1..k of the
# 690-sphere bed (empty or 0: none). The report covers every configuration of
# the study, with whatever records exist.
#
# ARM: where the two steppers' beds differ, halving each stepper's step decides
# which of them has not converged. An arm packs the same cases at a smaller step,
# its records in $(ARCHIVE)/$(ARM) (its runs in $(OUT)/$(ARM)), by default of the
# configurations $(HALVING_TUBES) and no 690-sphere beds (its step-halving is
# pipelines/step-convergence.sh's):
#   velocity-half   the velocity-level stepper at half its step (pack's default
#                   --step-travel and --max-step, halved)
#   force-quarter   the force-level stepper at a quarter of its substep
#                   (--stepper acceleration --substep-scale 0.25)
BIN ?= target/release
OUT ?= out/stepper-study
DOCS ?= docs/validation
ARCHIVE ?= $(DOCS)/stepper-study
REFERENCE ?= $(DOCS)/acceleration/runs
REPORT ?= $(DOCS)/stepper-study.md
NICE ?= nice
PYTHON ?= python3

# The paper's validation tubes of Table 3 at N = D/dp: spheres 3.1, 4.1, 6.1, 7.99;
# cylinders 3.55, 6.98, 9.16; rings 4.05, 6.02.
STUDY_TUBES := val-sphere-D31 val-sphere-D41 val-sphere-D61 val-sphere-D79.9 \
  val-cylinder-D35.49 val-cylinder-D69.83 val-cylinder-D91.58 \
  val-ring-D40.45 val-ring-D60.18
# The configurations whose porosities differ by more than two standard errors and
# whose force-level beds at a quarter of the substep take minutes, not hours.
HALVING_TUBES := val-sphere-D61 val-ring-D40.45
ARM ?=
SEEDS ?= 6
STUDY_ARCHIVE := $(ARCHIVE)
ifeq ($(ARM),)
TUBES ?= $(STUDY_TUBES)
SPHERE690_SEEDS ?= 20
ARM_KEYS := stepper = "velocity"
else
TUBES ?= $(HALVING_TUBES)
SPHERE690_SEEDS ?= 0
override OUT := $(OUT)/$(ARM)
override ARCHIVE := $(ARCHIVE)/$(ARM)
ifeq ($(ARM),force-quarter)
ARM_KEYS := stepper = "acceleration"\nsubstep-scale = 0.25
else ifeq ($(ARM),velocity-half)
# pack's own defaults, from its --help, so that the arm is exactly half of them.
pack_default = $(shell $(BIN)/pack --help | tr '\n' ' ' | sed -n 's/.*--$(1) <[A-Z]*> [^[]*\[default: \([0-9.e-]*\);.*/\1/p')
TRAVEL := $(call pack_default,step-travel)
MAX_STEP := $(call pack_default,max-step)
$(if $(TRAVEL),,$(error ARM=velocity-half: cannot read pack's default --step-travel from $(BIN)/pack --help; build pack first))
$(if $(MAX_STEP),,$(error ARM=velocity-half: cannot read pack's default --max-step from $(BIN)/pack --help; build pack first))
ARM_KEYS := stepper = "velocity"\nstep-travel = $(shell awk 'BEGIN { print $(TRAVEL) / 2 }')\nmax-step = $(shell awk 'BEGIN { print $(MAX_STEP) / 2 }')
else
$(error ARM=$(ARM): unknown arm; use velocity-half or force-quarter, or leave ARM empty for the study)
endif
endif

# The helper scripts sit beside this file, wherever make is run from.
THIS := $(lastword $(MAKEFILE_LIST))
PIPELINES := $(patsubst %/,%,$(dir $(THIS)))
HERE := $(PIPELINES)/stepper-study
PAPER := $(PIPELINES)/paper
TABLE ?= $(PAPER)/beds.csv
STUDY_TABLE ?= $(HERE)/beds.csv
RUNS := $(OUT)/runs
CASES := $(OUT)/cases
# SCHEDULER=slurm: each bed's stages as Slurm jobs ($(call sched,<id>) below).
include $(PIPELINES)/slurm/sched.mk

seeds = $(if $(filter-out 0,$(1)),$(shell seq 1 $(1)))
SPHERE690 := sph690-batch
TUBE_IDS := $(foreach t,$(TUBES),$(foreach s,$(call seeds,$(SEEDS)),$(t)-s$(s)))
SPHERE690_IDS := $(foreach s,$(call seeds,$(SPHERE690_SEEDS)),$(SPHERE690)-s$(s))
IDS := $(TUBE_IDS) $(SPHERE690_IDS)
RECORDS := $(patsubst %,$(ARCHIVE)/%.summary.json,$(IDS))

PELLETS := $(OUT)/sphere.pellet $(OUT)/cylinder.pellet $(OUT)/ring.pellet

.PHONY: beds report pellets
.SECONDARY:
# A recipe that fails half-way must not leave a file that looks finished.
.DELETE_ON_ERROR:

beds: $(RECORDS)
pellets: $(PELLETS)

# Every configuration of the study in the table's order (the study's tubes,
# then any other TUBES, then the 690-sphere bed), each from the records it has.
report:
	$(PYTHON) $(HERE)/report.py --table $(TABLE) --study-table $(STUDY_TABLE) \
	  --velocity $(STUDY_ARCHIVE) --reference $(REFERENCE) -o $(REPORT) \
	  --velocity-half $(STUDY_ARCHIVE)/velocity-half --force-quarter $(STUDY_ARCHIVE)/force-quarter \
	  $(STUDY_TUBES) $(filter-out $(STUDY_TUBES),$(TUBES)) $(SPHERE690)

$(OUT) $(RUNS) $(CASES) $(ARCHIVE):
	mkdir -p $@

# The paper's pellets (Table 3): sphere 10 mm, cylinder 10 × 10 mm, ring 10/6 × 10 mm.
$(OUT)/sphere.pellet: | $(OUT)
	$(BIN)/mkpellet sphere --diameter 10 -o $@
$(OUT)/cylinder.pellet: | $(OUT)
	$(BIN)/mkpellet cylinder --diameter 10 --height 10 -o $@
$(OUT)/ring.pellet: | $(OUT)
	$(BIN)/mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o $@

# The case file: the paper's (its first line, which names the paper study,
# replaced) or a row of this study's table, plus the stepper and the arm's step
# ($(ARM_KEYS)). Rewritten only when its text changes, so editing one row re-runs
# only that row's beds.
$(CASES)/%.toml: $(TABLE) $(STUDY_TABLE) $(PAPER)/case.awk $(HERE)/case.awk | $(CASES)
	config=$$(echo $* | sed 's/-s[0-9]*$$//'); \
	if awk -F, -v c=$$config '$$1 == c { found = 1 } END { exit !found }' $(STUDY_TABLE); then \
	  awk -F, -v id=$* -f $(HERE)/case.awk $(STUDY_TABLE) > $@.paper && \
	  { cat $@.paper; printf '%b\n' '$(ARM_KEYS)'; } > $@.tmp && rm -f $@.paper; \
	else \
	  awk -F, -v id=$* -f $(PAPER)/case.awk $(TABLE) > $@.paper && \
	  { echo "# packbed stepper study, bed $*: the paper's case with $(if $(ARM),the arm $(ARM),the velocity-level stepper)"; \
	    sed '1d; /^release-height/d' $@.paper; printf '%b\n' '$(ARM_KEYS)'; } > $@.tmp && rm -f $@.paper; \
	fi || { rm -f $@.tmp $@.paper; exit 2; }
	if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi

# pack exits 1 when --max-time is reached before the bed settles; the
# trajectory is complete then and kept (settle-check reports it unsettled).
# Any other failure (an interrupt, a kill) fails the recipe and leaves the
# run to `pack --resume`: the next `make` goes on from its last checkpoint,
# and pack.time adds up the legs. A partial run older than its case file is
# another bed's and is removed first.
PARTIAL = $(RUNS)/$*.run.mcap $(RUNS)/$*.run.mcap.part $(RUNS)/$*.run.mcap.resume
$(RUNS)/%.mcap: $(CASES)/%.toml $(PELLETS) | $(RUNS)
	partial=; for f in $(PARTIAL); do \
	  if [ -f $$f ] && [ $< -nt $$f ]; then rm -f $$f; fi; if [ -f $$f ]; then partial=1; fi; done; \
	  if [ -z "$$partial" ]; then rm -f $(RUNS)/$*.pack.time; fi
	$(call sched,$*) sh $(PAPER)/timed.sh -a $(RUNS)/$*.pack.time $(NICE) $(BIN)/pack --case $< -o $(RUNS)/$*.run.mcap --resume --quiet --threads $(THREADS) \
	  2> $(RUNS)/$*.pack.err || { cat $(RUNS)/$*.pack.err >&2; grep -q 'did not settle within --max-time' $(RUNS)/$*.pack.err; }
	rm -f $(RUNS)/$*.pack.err
	mv $(RUNS)/$*.run.mcap $@

# settle-check exits 1 for a bed that did not settle: its last frame is kept.
$(RUNS)/%.packing: $(RUNS)/%.mcap
	$(call sched,$*) sh $(PAPER)/timed.sh $(RUNS)/$*.settle.time $(NICE) $(BIN)/settle-check $< -o $@ --csv $(RUNS)/$*.poses.csv \
	  --json > $(RUNS)/$*.settle.json.tmp || test $$? -eq 1
	mv $(RUNS)/$*.settle.json.tmp $(RUNS)/$*.settle.json

$(RUNS)/%.summary.json: $(RUNS)/%.packing
	$(call sched,$*) sh $(PAPER)/timed.sh $(RUNS)/$*.voidprof.time $(NICE) $(BIN)/voidprof $< \
	  --window $$(sed -n 's/^# voidprof-window: //p' $(CASES)/$*.toml) -o $(RUNS)/$*.profile.csv --summary $@

# The record: the run's small files, the summary last (it marks the record
# complete). No prerequisites (see the head of this file) but its directory,
# and for a bed still to run the pellets, made here once so that two beds run
# by `make -j2` do not both write them.
RECORD := profile.csv poses.csv settle.json pack.time settle.time voidprof.time
$(filter-out $(wildcard $(RECORDS)),$(RECORDS)): | $(PELLETS)
$(ARCHIVE)/%.summary.json: | $(ARCHIVE)
	+$(MAKE) --no-print-directory -f $(THIS) $(RUNS)/$*.summary.json
	for f in $(RECORD); do \
	  if test -f $(RUNS)/$*.$$f; then cp $(RUNS)/$*.$$f $(ARCHIVE)/$*.$$f.tmp && mv $(ARCHIVE)/$*.$$f.tmp $(ARCHIVE)/$*.$$f; fi; \
	done
	cp $(RUNS)/$*.summary.json $@.tmp && mv $@.tmp $@
