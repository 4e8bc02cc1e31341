# The default pipeline, run by `make`: the paper's three pellets
# (Mohammadzadeh Moghaddam et al. 2018, Table 3) made and described.
# Later stages (pack, settle-check, voidprof, compare) extend this file.
BIN ?= target/release
OUT ?= out

PELLETS := $(OUT)/sphere.pellet $(OUT)/cylinder.pellet $(OUT)/ring.pellet

.PHONY: all
all: $(PELLETS)
	@for p in $(PELLETS); do echo "== $$p"; $(BIN)/mkpellet info $$p || exit 2; done
	@echo "== pellet files and STL meshes (mm) are in $(OUT)/"

$(OUT):
	mkdir -p $@

$(OUT)/sphere.pellet: $(BIN)/mkpellet | $(OUT)
	$(BIN)/mkpellet sphere --diameter 10 -o $@ --stl $(OUT)/sphere.stl

$(OUT)/cylinder.pellet: $(BIN)/mkpellet | $(OUT)
	$(BIN)/mkpellet cylinder --diameter 10 --height 10 -o $@ --stl $(OUT)/cylinder.stl

$(OUT)/ring.pellet: $(BIN)/mkpellet | $(OUT)
	$(BIN)/mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o $@ --stl $(OUT)/ring.stl
