# polyscene: the two user commands are `make demo` and `make test`.
# Every target installs what it needs first (idempotent, quick when present).
SHELL := /bin/bash
PORT ?= 8080

.PHONY: setup build demo test bench repro clean help

help:
	@echo "make demo   - set up, build and serve the page on http://127.0.0.1:$(PORT) (PORT=NNNN to change)"
	@echo "make test   - set up and run every test (Rust, wasm, Node, browser)"
	@echo "make build  - build the JS package: pkg/web, pkg/node, and the npm tarball pkg/polyscene-*.tgz"
	@echo "make bench  - native criterion benchmarks and the wasm benchmark (prints tables)"
	@echo "make repro  - reproduce the paper's evaluation into REPRODUCTION.md"

setup:
	scripts/setup.sh all

build:
	scripts/setup.sh rust npm
	scripts/pack.sh

demo:
	scripts/setup.sh rust npm
	scripts/build-wasm.sh
	scripts/serve.sh $(PORT)

test:
	scripts/setup.sh all
	scripts/test.sh

bench:
	scripts/setup.sh rust npm
	scripts/bench.sh

repro:
	scripts/setup.sh rust npm
	scripts/repro.sh

clean:
	cargo clean
	rm -rf pkg www/pkg
