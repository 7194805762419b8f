# The two commands of the README, and their parts.
#   make render   the main job: the default scene (Cornell box) with HVL GI to out/cornell-box.png
#   make test     formatting, lints and the whole test suite on the Vulkan device (lavapipe in CI)

CARGO ?= cargo

.PHONY: deps render info test fmt-check clippy unit

deps:
	./scripts/install-deps.sh

render: deps
	mkdir -p out
	$(CARGO) run --release -- render builtin:cornell-box --width 512 --height 512 -o out/cornell-box.png

info: deps
	$(CARGO) run --release -- info

test: deps fmt-check clippy unit

fmt-check:
	$(CARGO) fmt --all -- --check

clippy:
	$(CARGO) clippy --workspace --all-targets -- -D warnings

unit:
	$(CARGO) test --workspace
