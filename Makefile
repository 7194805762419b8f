# The two commands of the README, and their parts.
#   make render   the main job (today: the device report; a rendered frame once the frame lands)
#   make test     formatting, lints and the whole test suite on the Vulkan device (lavapipe in CI)

CARGO ?= cargo

.PHONY: deps render info test fmt-check clippy unit

deps:
	./scripts/install-deps.sh

render: info

info: deps
	$(CARGO) run --release -- info

test: deps fmt-check clippy unit

fmt-check:
	$(CARGO) fmt --all -- --check

clippy:
	$(CARGO) clippy --workspace --all-targets -- -D warnings

unit:
	$(CARGO) test --workspace
