# The paper's study (Mohammadzadeh Moghaddam et al. 2018), bed by
# bed: one case file per bed made from the table $(TABLE), then
# pack → settle-check → voidprof, and paper-report over whatever has
# finished. Every file is a Make target, so a re-run skips finished beds and
# `make -j2` runs two beds at once (each recipe writes only its own bed's files).
#
# A finished bed's record (summary, profile, settle report, stage times; the
# poses too, except for validation beds, whose poses the report keeps in
# $(DOCS)/beds) is copied into $(ARCHIVE), which is committed with the report.
# The record is the bed's target and has no prerequisites, so a bed finished
# once is not run again, in this checkout or any clone, and the report can be
# regenerated without the trajectories in $(OUT). To run a bed again (a new
# engine, say), delete its record: rm $(ARCHIVE)/<id>.* $(RUNS)/<id>.*
#
#   make -f pipelines/paper.mk validation|loading|cor|friction|all   the beds
#   make -f pipelines/paper.mk report                                 docs from what exists
#
# REPEATS=k keeps seeds 1..k of every row (the table's own count otherwise).
# A bed that reaches pack's --max-time without settling is kept (its
# trajectory is complete) and reported as not settled, not retried.
BIN ?= target/release
OUT ?= out/paper
DOCS ?= docs/validation
ARCHIVE ?= $(DOCS)/runs
# Partial runs parked by `park` (pack --park: the checkpoint without the
# frames), committed so that a bed longer than one machine's slot goes on elsewhere.
PARKED ?= $(DOCS)/parked
TABLE ?= pipelines/paper/beds.csv
REPEATS ?=
NICE ?= nice
# The helper scripts sit beside this file, wherever make is run from.
THIS := $(lastword $(MAKEFILE_LIST))
HERE := $(patsubst %/,%,$(dir $(THIS)))/paper
RUNS := $(OUT)/runs
CASES := $(OUT)/cases
# SCHEDULER=slurm: each bed's stages as Slurm jobs ($(call sched,<id>) below).
include $(patsubst %/,%,$(dir $(THIS)))/slurm/sched.mk

ids = $(shell awk -F, -v study=$(1) -v repeats=$(REPEATS) -f $(HERE)/ids.awk $(TABLE))
done_of = $(patsubst %,$(ARCHIVE)/%.summary.json,$(1))

VALIDATION := $(call ids,validation)
LOADING := $(call ids,loading)
COR := $(call ids,cor)
FRICTION := $(call ids,friction)

PELLETS := $(OUT)/sphere.pellet $(OUT)/cylinder.pellet $(OUT)/ring.pellet

.PHONY: all validation loading cor friction report pellets park
.SECONDARY:
# A recipe that fails half-way must not leave a file that looks finished.
.DELETE_ON_ERROR:

all: validation loading cor friction
validation: $(call done_of,$(VALIDATION))
loading: $(call done_of,$(LOADING))
cor: $(call done_of,$(COR))
friction: $(call done_of,$(FRICTION))
pellets: $(PELLETS)

report:
	$(BIN)/paper-report --table $(TABLE) --runs $(ARCHIVE) $(if $(wildcard $(RUNS)),--runs $(RUNS)) \
	  $(if $(REPEATS),--repeats $(REPEATS)) -o $(DOCS)

# Park every partial run in $(RUNS) (stop its pack first: a running pack
# holds its output's lock, and park refuses it): a copy holding what
# `pack --resume` needs, and the pack time of its legs so far. The next run
# of the bed, in any clone, starts from that copy when $(RUNS) has none.
PARTIAL_IDS = $(sort $(foreach f,$(wildcard $(RUNS)/*.run.mcap $(RUNS)/*.run.mcap.part $(RUNS)/*.run.mcap.resume),\
  $(firstword $(subst .run.mcap, ,$(notdir $(f))))))
park: | $(PARKED)
	@for id in $(PARTIAL_IDS); do \
	  $(BIN)/pack --case $(CASES)/$$id.toml -o $(RUNS)/$$id.run.mcap --park $(PARKED)/$$id.run.mcap || exit 1; \
	  if [ -f $(RUNS)/$$id.pack.time ]; then cp $(RUNS)/$$id.pack.time $(PARKED)/$$id.pack.time; fi; \
	done

$(OUT) $(RUNS) $(CASES) $(ARCHIVE) $(PARKED):
	mkdir -p $@

# The paper's pellets (Table 3): sphere 10 mm, cylinder 10 × 10 mm, ring 10/6 × 10 mm.
$(OUT)/sphere.pellet: | $(OUT)
	$(BIN)/mkpellet sphere --diameter 10 -o $@
$(OUT)/cylinder.pellet: | $(OUT)
	$(BIN)/mkpellet cylinder --diameter 10 --height 10 -o $@
$(OUT)/ring.pellet: | $(OUT)
	$(BIN)/mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o $@

# The case file is rewritten only when its text changes, so editing one row
# of the table re-runs only that row's beds. STEPPER=acceleration packs the
# beds with the paper's force-level formulation (pack's default stepper
# otherwise); $(OUT)/stepper records the choice, so changing it rewrites the
# case files. A bed with a record is not run again, so give such a study its
# own DOCS (and ARCHIVE).
STEPPER ?=
# Every bed's make checks it, two at a time under -j: each writes its own temporary.
$(OUT)/stepper: FORCE | $(OUT)
	echo '$(STEPPER)' > $@.$$$$ && if cmp -s $@.$$$$ $@; then rm -f $@.$$$$; else mv $@.$$$$ $@; fi
.PHONY: FORCE
FORCE:
$(CASES)/%.toml: $(TABLE) $(HERE)/case.awk $(OUT)/stepper | $(CASES)
	{ awk -F, -v id=$* -f $(HERE)/case.awk $(TABLE) && $(if $(STEPPER),echo 'stepper = "$(STEPPER)"',true); } > $@.tmp
	if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi

# pack exits 1 when --max-time is reached before the bed settles; the
# trajectory is complete then and kept (settle-check reports it unsettled).
# Any other failure (an interrupt, a kill) fails the recipe and leaves the
# run to `pack --resume`: the next `make` goes on from its last checkpoint,
# and pack.time adds up the legs. A partial run older than its case file is
# another bed's and is removed first; without a partial run the time starts
# from zero, unless a parked run ($(PARKED), see `park`) is there to be
# copied in, with its pack time.
PARTIAL = $(RUNS)/$*.run.mcap $(RUNS)/$*.run.mcap.part $(RUNS)/$*.run.mcap.resume
$(RUNS)/%.mcap: $(CASES)/%.toml $(PELLETS) | $(RUNS)
	partial=; for f in $(PARTIAL); do \
	  if [ -f $$f ] && [ $< -nt $$f ]; then rm -f $$f; fi; if [ -f $$f ]; then partial=1; fi; done; \
	  if [ -z "$$partial" ]; then rm -f $(RUNS)/$*.pack.time; \
	  if [ -f $(PARKED)/$*.run.mcap ]; then cp $(PARKED)/$*.run.mcap $(RUNS)/$*.run.mcap; \
	  if [ -f $(PARKED)/$*.pack.time ]; then cp $(PARKED)/$*.pack.time $(RUNS)/$*.pack.time; fi; fi; fi
	$(call sched,$*) sh $(HERE)/timed.sh -a $(RUNS)/$*.pack.time $(NICE) $(BIN)/pack --case $< -o $(RUNS)/$*.run.mcap --resume --quiet --threads $(THREADS) \
	  2> $(RUNS)/$*.pack.err || { cat $(RUNS)/$*.pack.err >&2; grep -q 'did not settle within --max-time' $(RUNS)/$*.pack.err; }
	rm -f $(RUNS)/$*.pack.err
	mv $(RUNS)/$*.run.mcap $@

# settle-check exits 1 for a bed that did not settle: its last frame is kept.
$(RUNS)/%.packing: $(RUNS)/%.mcap
	$(call sched,$*) sh $(HERE)/timed.sh $(RUNS)/$*.settle.time $(NICE) $(BIN)/settle-check $< -o $@ --csv $(RUNS)/$*.poses.csv \
	  --json > $(RUNS)/$*.settle.json.tmp || test $$? -eq 1
	mv $(RUNS)/$*.settle.json.tmp $(RUNS)/$*.settle.json

$(RUNS)/%.summary.json: $(RUNS)/%.packing
	$(call sched,$*) sh $(HERE)/timed.sh $(RUNS)/$*.voidprof.time $(NICE) $(BIN)/voidprof $< \
	  --window $$(sed -n 's/^# voidprof-window: //p' $(CASES)/$*.toml) -o $(RUNS)/$*.profile.csv --summary $@

# The record: the run's small files, the summary last (it marks the record
# complete). No prerequisites: see the head of this file.
RECORD := profile.csv settle.json pack.time settle.time voidprof.time
$(ARCHIVE)/%.summary.json: | $(ARCHIVE)
	+$(MAKE) --no-print-directory -f $(THIS) $(RUNS)/$*.summary.json
	for f in $(RECORD) $(if $(filter $*,$(VALIDATION)),,poses.csv); do \
	  if test -f $(RUNS)/$*.$$f; then cp $(RUNS)/$*.$$f $(ARCHIVE)/$*.$$f.tmp && mv $(ARCHIVE)/$*.$$f.tmp $(ARCHIVE)/$*.$$f; fi; \
	done
	cp $(RUNS)/$*.summary.json $@.tmp && mv $@.tmp $@
	rm -f $(PARKED)/$*.run.mcap $(PARKED)/$*.pack.time
