# T14 (integration sanity, not analytic): 1000 spheres of
# 10 mm in a 100 mm tube (N = D/d = 10), every pellet released at once as a
# loose cloud (`pack --scheme batch`), then the chain: settle-check, voidprof,
# compare. Checks, printed at the end: the bulk porosity against the grade A/B
# correlations at N = 10 (Dixon 0.409, Foumeny, Benyahia & O'Neill, Cheng,
# Sato) and the radial void fraction, which must be 1 at the wall with its
# first minimum near 0.5 d. Run with `make t14` (one core; see the README for
# the measured time). SEED= picks the cloud.
BIN ?= target/release
OUT ?= out/t14
SEED ?= 1
# Bulk porosity and profile over z = 0–80 mm of a bed about 110 mm tall.
WINDOW := 0,80
# SCHEDULER=slurm: the bed's stages as Slurm jobs ($(call sched,bed) below).
include $(patsubst %/,%,$(dir $(lastword $(MAKEFILE_LIST))))/slurm/sched.mk

.PHONY: all
all: $(OUT)/report/scores.json
	@echo "== T14: 1000 spheres, D = 100 mm, batch loading, seed $(SEED)"
	@grep -m1 '"settled"' $(OUT)/settle.json; grep -m1 '"settle_time_s"' $(OUT)/settle.json
	@grep -m1 '"bulk_porosity"' $(OUT)/summary.json
	@cat $(OUT)/report/scores.csv
	@awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$$i] = i; next } \
	  { z = $$c["wall_distance_dp"]; e = $$c["void_fraction"]; \
	    if (wz == "" || z < wz) { wz = z; we = e } \
	    if (z > 0.2 && z < 1.0 && (best == "" || e < best)) { best = e; at = z } } \
	  END { printf "wall: void fraction %.4f at z = %.3f dp\n", we, wz; \
	        printf "first minimum: void fraction %.4f at z = %.3f dp (literature: about 0.5 dp)\n", best, at }' $(OUT)/profile.csv
	@echo "== plot: $(OUT)/report/profile.png; report: $(OUT)/report/report.md"

$(OUT):
	mkdir -p $@

$(OUT)/sphere.pellet: | $(OUT)
	$(BIN)/mkpellet sphere --diameter 10 -o $@

$(OUT)/bed.mcap: $(OUT)/sphere.pellet
	$(call sched,bed) $(BIN)/pack --pellet $< --tube-diameter 100 --count 1000 --scheme batch --seed $(SEED) --threads $(THREADS) -o $@

$(OUT)/bed.packing: $(OUT)/bed.mcap
	$(call sched,bed) $(BIN)/settle-check $< -o $@ --csv $(OUT)/poses.csv --json > $(OUT)/settle.json

$(OUT)/profile.csv: $(OUT)/bed.packing
	$(call sched,bed) $(BIN)/voidprof $< --window $(WINDOW) -o $@ --summary $(OUT)/summary.json

$(OUT)/report/scores.json: $(OUT)/profile.csv
	$(call sched,bed) $(BIN)/compare --profile $< --summary $(OUT)/summary.json \
	  --ref dixon-1988,foumeny-1993,benyahia-oneill-2005,cheng-2011,sato-1973,de-klerk-2003,mueller-1992 -o $(OUT)/report/
