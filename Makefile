# stancelib: the two commands a newcomer needs are `make demo` and `make test`.
CARGO ?= cargo

.PHONY: demo test lint bench nightly build doc golden fixtures

## Run the main job on the bundled fixtures (pipelines/demo.toml); tables go to out/demo/.
demo:
	$(CARGO) run --release -- run pipelines/demo.toml

## Every test: unit, integration (real clips from ../shared/data when present) and doc tests.
test:
	$(CARGO) test --all-targets
	$(CARGO) test --doc

## Formatting and clippy, warnings as errors.
lint:
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings

## Criterion benchmarks (parse, FK+COM, ingest) on the shared clips.
bench:
	$(CARGO) bench --bench stages

## The nightly job over ../shared/data (pipelines/nightly.toml).
nightly:
	$(CARGO) run --release -- run pipelines/nightly.toml

build:
	$(CARGO) build --release

doc:
	$(CARGO) doc --no-deps

## Re-generate the golden files of the tests (review the diff before committing).
golden:
	UPDATE_GOLDEN=1 $(CARGO) test --test integration

## Re-generate fixtures/bvh from the project's own generator (see fixtures/README.md).
fixtures:
	$(CARGO) test --test integration fixtures_are_generated -- --ignored
