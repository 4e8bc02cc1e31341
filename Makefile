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

clean:
	rm -rf $(OUT)
