# The default pipeline, run by `make`: the paper's three pellets
# (Mohammadzadeh Moghaddam et al. 2018, Table 3) made and described, then a
# small sphere bed taken through the whole chain:
# mkpellet → pack → settle-check → voidprof → compare, and bedexport last
# (under a second): the bed as STL, VTK and voxels for CFD / LBM codes.
BIN ?= target/release
OUT ?= out

PELLETS := $(OUT)/sphere.pellet $(OUT)/cylinder.pellet $(OUT)/ring.pellet
# 40 spheres of 10 mm in a 40 mm tube (N = 4): settles in about 2 s of
# simulated time; the profile is counted over the bottom 25 mm of the bed.
BED_ARGS ?= --tube-diameter 40 --count 40 --seed 1
WINDOW ?= 0,25
comma := ,
# SCHEDULER=slurm: the bed's stages as Slurm jobs ($(call sched,bed) below).
# This file's directory (pipelines/), wherever make runs.
PIPELINES := $(patsubst %/,%,$(dir $(lastword $(MAKEFILE_LIST))))
include $(PIPELINES)/slurm/sched.mk

# A recipe that fails leaves no target behind: settle-check exits 1 on a bed
# that did not settle, after writing its last frame, which must not be scored.
.DELETE_ON_ERROR:

# Each tool's own output goes to $(OUT)/log/<target>.log; a failing tool's last
# lines and exit status reach the terminal (pipelines/logged.sh).
RUN = sh $(PIPELINES)/logged.sh $(OUT)/log/$(@F).log

.PHONY: all pellets
all: $(OUT)/pellets.txt $(OUT)/report/scores.json $(OUT)/bed.stl
	@echo "built: 3 pellets; a bed of 10 mm spheres (pack $(BED_ARGS)), profiled over z = $(subst $(comma), to ,$(WINDOW)) mm"
	@echo "outputs in $(OUT)/: pellets.txt, bed.packing, poses.csv, profile.csv, summary.json, report/, bed.stl, tube.stl, bed.vtp, bed.raw"
	@echo "each tool's own output: $(OUT)/log/"
	@echo "scores (CSV: $(OUT)/report/scores.csv; report: $(OUT)/report/report.md):"
	@sed 's/^/  /' $(OUT)/report/scores.txt
	@echo "plot: $(OUT)/report/profile.png (also .svg)"

pellets: $(OUT)/pellets.txt

# The pellets' properties (mkpellet info), one after the other.
$(OUT)/pellets.txt: $(PELLETS) $(BIN)/mkpellet
	@for p in $(PELLETS); do echo "== $$p"; $(BIN)/mkpellet info $$p || exit 2; done >$@

$(OUT)/sphere.pellet: $(BIN)/mkpellet
	@$(RUN) $(BIN)/mkpellet sphere --diameter 10 -o $@ --stl $(OUT)/sphere.stl

$(OUT)/cylinder.pellet: $(BIN)/mkpellet
	@$(RUN) $(BIN)/mkpellet cylinder --diameter 10 --height 10 -o $@ --stl $(OUT)/cylinder.stl

$(OUT)/ring.pellet: $(BIN)/mkpellet
	@$(RUN) $(BIN)/mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o $@ --stl $(OUT)/ring.stl

# pack runs on bed.run.mcap, renamed only once the bed settled (exit 0): an
# interrupted or killed run, or one past its --max-time, stays there for the
# next make's --resume instead of becoming bed.mcap.
$(OUT)/bed.mcap: $(OUT)/sphere.pellet $(BIN)/pack
	@$(RUN) $(call sched,bed) $(BIN)/pack --pellet $< $(BED_ARGS) -o $(OUT)/bed.run.mcap --resume
	@mv $(OUT)/bed.run.mcap $@

$(OUT)/bed.packing: $(OUT)/bed.mcap $(BIN)/settle-check
	@$(RUN) $(call sched,bed) $(BIN)/settle-check $< -o $@ --csv $(OUT)/poses.csv

$(OUT)/profile.csv: $(OUT)/bed.packing $(BIN)/voidprof
	@$(RUN) $(call sched,bed) $(BIN)/voidprof $< --window $(WINDOW) -o $@ --summary $(OUT)/summary.json --plot $(OUT)/profile.png

# scores.txt: the scores as an aligned table (compare --table), printed by `all`.
$(OUT)/report/scores.json: $(OUT)/profile.csv $(BIN)/compare
	@$(RUN) $(call sched,bed) $(BIN)/compare --profile $< --summary $(OUT)/summary.json --ref mueller-1992,de-klerk-2003,dixon-1988 -o $(OUT)/report/ --table $(OUT)/report/scores.txt

# The export for CFD and LBM codes (tools/bedexport/README.md).
$(OUT)/bed.stl: $(OUT)/bed.packing $(BIN)/bedexport
	@$(RUN) $(call sched,bed) $(BIN)/bedexport $< --stl $@ --tube-stl $(OUT)/tube.stl --vtk $(OUT)/bed.vtp --vtk-centres $(OUT)/centres.vtp --voxels $(OUT)/bed.raw
