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
# SCHEDULER=slurm: the bed's stages as Slurm jobs ($(call sched,bed) below).
include $(patsubst %/,%,$(dir $(lastword $(MAKEFILE_LIST))))/slurm/sched.mk

# A recipe that fails leaves no target behind: settle-check exits 1 on a bed
# that did not settle, after writing its last frame, which must not be scored.
.DELETE_ON_ERROR:

.PHONY: all pellets
all: pellets $(OUT)/report/scores.json $(OUT)/bed.stl
	@echo "== scores ($(OUT)/report/scores.json)"
	@cat $(OUT)/report/scores.csv
	@echo "== plot: $(OUT)/report/profile.png (also .svg); report: $(OUT)/report/report.md"
	@echo "== CFD/LBM export: $(OUT)/bed.stl, $(OUT)/tube.stl (mm), $(OUT)/bed.vtp, $(OUT)/bed.raw (+ .json)"

pellets: $(PELLETS)
	@for p in $(PELLETS); do echo "== $$p"; $(BIN)/mkpellet info $$p || exit 2; done

$(OUT):
	mkdir -p $@

$(OUT)/sphere.pellet: $(BIN)/mkpellet | $(OUT)
	$(BIN)/mkpellet sphere --diameter 10 -o $@ --stl $(OUT)/sphere.stl

$(OUT)/cylinder.pellet: $(BIN)/mkpellet | $(OUT)
	$(BIN)/mkpellet cylinder --diameter 10 --height 10 -o $@ --stl $(OUT)/cylinder.stl

$(OUT)/ring.pellet: $(BIN)/mkpellet | $(OUT)
	$(BIN)/mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o $@ --stl $(OUT)/ring.stl

# pack runs on bed.run.mcap, renamed only once the bed settled (exit 0): an
# interrupted or killed run, or one past its --max-time, stays there for the
# next make's --resume instead of becoming bed.mcap.
$(OUT)/bed.mcap: $(OUT)/sphere.pellet $(BIN)/pack
	$(call sched,bed) $(BIN)/pack --pellet $< $(BED_ARGS) -o $(OUT)/bed.run.mcap --resume
	mv $(OUT)/bed.run.mcap $@

$(OUT)/bed.packing: $(OUT)/bed.mcap $(BIN)/settle-check
	$(call sched,bed) $(BIN)/settle-check $< -o $@ --csv $(OUT)/poses.csv

$(OUT)/profile.csv: $(OUT)/bed.packing $(BIN)/voidprof
	$(call sched,bed) $(BIN)/voidprof $< --window $(WINDOW) -o $@ --summary $(OUT)/summary.json --plot $(OUT)/profile.png

$(OUT)/report/scores.json: $(OUT)/profile.csv $(BIN)/compare
	$(call sched,bed) $(BIN)/compare --profile $< --summary $(OUT)/summary.json --ref mueller-1992,de-klerk-2003,dixon-1988 -o $(OUT)/report/

# The export for CFD and LBM codes (tools/bedexport/README.md).
$(OUT)/bed.stl: $(OUT)/bed.packing $(BIN)/bedexport
	$(call sched,bed) $(BIN)/bedexport $< --stl $@ --tube-stl $(OUT)/tube.stl --vtk $(OUT)/bed.vtp --vtk-centres $(OUT)/centres.vtp --voxels $(OUT)/bed.raw
