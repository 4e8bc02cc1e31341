# packbed: `make` builds (release) and runs the default pipeline;
# `make test` runs formatting, lints, docs and every test.
CARGO ?= cargo
OUT ?= out
BIN := target/release

.PHONY: all build pipeline test lint doc bench clean

all: pipeline

build:
	$(CARGO) build --release --workspace --bins

pipeline: build
	$(MAKE) --no-print-directory -f pipelines/default.mk BIN=$(BIN) OUT=$(OUT)

lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

doc:
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps

test: lint doc
	$(CARGO) build --workspace --bins
	$(CARGO) test --workspace

# Speed figures (not tests): the engine pouring spheres, voidprof and
# bedexport's stages on a 600-sphere bed. PELLET_BENCH_SIZES / _SIM_SECONDS /
# _WALL_SECONDS tune the first.
bench:
	PELLET_BENCH_EXACT_ROWS=$${PELLET_BENCH_EXACT_ROWS:-16} $(CARGO) bench -p pellet_sim --bench pack_spheres
	$(CARGO) bench -p pellet_sim --bench pack_cylinders
	$(CARGO) run --release -p pellet_analysis --example bench_voidprof
	$(CARGO) run --release -p pellet_export --example bench_export

clean:
	rm -rf $(OUT)
