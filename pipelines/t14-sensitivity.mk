# The sensitivity half of T14: the T14 bed (1000 spheres of 10 mm,
# D = 100 mm, batch loading; pipelines/t14.mk) packed again with one setting
# changed at a time, to show how much the bulk porosity depends on εp, on the
# pellet–pellet friction μ and on the friction rule, against the spread of
# three seeds of the unchanged bed. Every bed is one Make target, so a re-run
# skips finished beds and `make -j2` runs two at once.
#
#   make -f pipelines/t14-sensitivity.mk            all beds, then the table
#   make -f pipelines/t14-sensitivity.mk table      the table from what exists
#
# Writes $(OUT)/<variant>/{bed.mcap,bed.packing,summary.json,...} and
# $(OUT)/sensitivity.md. One bed takes about 5 minutes of one core (README).
BIN ?= target/release
OUT ?= out/t14-sensitivity
NICE ?= nice
# The T14 bed; smaller values only to try the pipeline out.
COUNT ?= 1000
TUBE ?= 100
# Bulk porosity windows, z in mm: as T14, and away from the floor's ordering.
WINDOW ?= 0,80
INNER ?= 20,80
# Writes "<wall seconds> <exit code>" of a command (shared with the paper study).
TIMED := $(patsubst %/,%,$(dir $(lastword $(MAKEFILE_LIST))))/paper/timed.sh
# SCHEDULER=slurm: each bed's stages as Slurm jobs ($(call sched,<variant>) below).
include $(patsubst %/,%,$(dir $(lastword $(MAKEFILE_LIST))))/slurm/sched.mk

# Variant name → pack flags on top of the T14 bed (seed 1 unless given).
# base: the T14 bed (recommended model: static friction at resting contacts,
# stick clamp, velocity bias; εp = 5e-3 m/s; μ = 0.1 between pellets, 0.6 at
# the wall). paper: resting contacts frictionless, zero clamp, no bias; such a
# bed never settles (README, Known limits), so it is stopped at 1.5 s of
# simulated time (the base bed settles in about 0.9 s) and measured as it
# is then.
flags_base-s1 := --seed 1
flags_base-s2 := --seed 2
flags_base-s3 := --seed 3
flags_eps-0.0025 := --resting-band 0.0025
flags_eps-0.01 := --resting-band 0.01
flags_mu-0.05 := --friction 0.05
flags_mu-0.3 := --friction 0.3
flags_mu-0.6 := --friction 0.6
flags_clamp-zero := --friction-clamp zero
flags_paper := --contact-model paper --max-time 1.5

# In the order they run with -j1: one of each kind first.
VARIANTS ?= base-s1 eps-0.0025 eps-0.01 mu-0.05 mu-0.3 clamp-zero paper base-s2 base-s3 mu-0.6
# What the table says each variant changes.
what_base-s1 := T14 bed, seed 1
what_base-s2 := seed 2
what_base-s3 := seed 3
what_eps-0.0025 := εp = 2.5e-3 m/s (substep cap 1.27e-4 s)
what_eps-0.01 := εp = 1e-2 m/s
what_mu-0.05 := μ = 0.05 between pellets
what_mu-0.3 := μ = 0.3 between pellets
what_mu-0.6 := μ = 0.6 between pellets
what_clamp-zero := friction rule Z (zero clamp)
what_paper := paper model (no resting friction, Z, no bias), stopped at 1.5 s

.PHONY: all table
.SECONDARY:
.DELETE_ON_ERROR:

all: $(foreach v,$(VARIANTS),$(OUT)/$(v)/summary.json)
	@$(MAKE) --no-print-directory -f $(firstword $(MAKEFILE_LIST)) BIN=$(BIN) OUT=$(OUT) VARIANTS="$(VARIANTS)" table

$(OUT):
	mkdir -p $@

$(OUT)/sphere.pellet: | $(OUT)
	$(BIN)/mkpellet sphere --diameter 10 -o $@

# pack exits 1 when --max-time ends the run before the bed settles (the paper
# variant); the trajectory is complete then, and settle-check says so.
$(OUT)/%/bed.mcap: $(OUT)/sphere.pellet
	mkdir -p $(@D)
	rm -f $(@D)/run.mcap
	$(call sched,$*) sh $(TIMED) $(@D)/pack.time $(NICE) $(BIN)/pack --pellet $< --tube-diameter $(TUBE) \
	  --count $(COUNT) --scheme batch $(flags_$*) --threads $(THREADS) -o $(@D)/run.mcap --quiet || test -f $(@D)/run.mcap
	mv $(@D)/run.mcap $@

# settle-check exits 1 for a bed that did not settle: its last frame is kept.
$(OUT)/%/bed.packing: $(OUT)/%/bed.mcap
	$(call sched,$*) $(BIN)/settle-check $< -o $@ --json > $(@D)/settle.json.tmp || test $$? -eq 1
	mv $(@D)/settle.json.tmp $(@D)/settle.json

$(OUT)/%/summary.json: $(OUT)/%/bed.packing
	$(call sched,$*) $(BIN)/voidprof $< --window $(INNER) -o $(@D)/profile-inner.csv --summary $(@D)/summary-inner.json
	$(call sched,$*) $(BIN)/voidprof $< --window $(WINDOW) -o $(@D)/profile.csv --summary $@

comma := ,
json = $$(sed -n 's/^  "$(2)": \([^,]*\),*$$/\1/p' $(1) | head -1)

table:
	@{ echo '| variant | changed | settled | time (s) | ε, z = $(subst $(comma),–,$(WINDOW)) mm | ε, z = $(subst $(comma),–,$(INNER)) mm | pack wall time |'; \
	  echo '|---|---|---|---|---|---|---|'; \
	  row() { d=$(OUT)/$$1; test -f $$d/summary.json || return 0; \
	    printf '| %s | %s | %s | %.3f | %.4f | %.4f | %s |\n' $$1 "$$2" \
	      $(call json,$$d/settle.json,settled) $(call json,$$d/settle.json,final_time_s) \
	      $(call json,$$d/summary.json,bulk_porosity) $(call json,$$d/summary-inner.json,bulk_porosity) \
	      "$$(awk '{ printf "%.0f s", $$1 }' $$d/pack.time)"; }; \
	  $(foreach v,$(VARIANTS),row $(v) "$(what_$(v))";) } > $(OUT)/sensitivity.md
	@cat $(OUT)/sensitivity.md
