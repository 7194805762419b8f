# The two commands of the README, and their parts.
#   make render   the main job: the default scene (Cornell box) with HVL GI to out/cornell-box.png
#   make test     formatting, lints, the API docs' links and the whole test suite on the Vulkan
#                 device (lavapipe in CI)

CARGO ?= cargo

.PHONY: deps render info test fmt-check clippy doc unit

deps:
	./scripts/install-deps.sh

render: deps
	mkdir -p out
	$(CARGO) run --release -- render builtin:cornell-box --width 512 --height 512 -o out/cornell-box.png

info: deps
	$(CARGO) run --release -- info

test: deps fmt-check clippy doc unit

fmt-check:
	$(CARGO) fmt --all -- --check

clippy:
	$(CARGO) clippy --workspace --all-targets -- -D warnings

# Every intra-doc link resolves and no public item's docs point at a private one.
doc:
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps

unit:
	$(CARGO) test --workspace
