# stancelib: the two commands a newcomer needs are `make demo` and `make test`.
CARGO ?= cargo

.PHONY: demo test lint bench nightly build install doc fixtures fuzz

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

## Mutation fuzzer of the reader and ingest for STANCELIB_FUZZ_SECS seconds (default 300);
## failing inputs are saved under fixtures/regressions/ (replayed by `make test`).
STANCELIB_FUZZ_SECS ?= 300
fuzz:
	STANCELIB_FUZZ_SECS=$(STANCELIB_FUZZ_SECS) $(CARGO) test --test integration \
		safety_inputs::mutation_fuzz_for_a_time_budget -- --ignored --nocapture

## Criterion benchmarks: parse, FK+COM, ingest (stages); full library build, 10k stances
## (library); candidate evaluations and the 200 × 200 jump map (queries); 2PAC H-rep,
## transition QP and 10-phase trajectory (twopac).
## They run in the `profiling` profile (release code with line tables, for perf).
bench:
	$(CARGO) bench --profile profiling --bench stages
	$(CARGO) bench --profile profiling --bench library
	$(CARGO) bench --profile profiling --bench queries
	$(CARGO) bench --profile profiling --bench twopac

## The nightly job over ../shared/data (pipelines/nightly.toml).
nightly:
	$(CARGO) run --release -- run pipelines/nightly.toml

## The release binary: target/release/stancelib (or $$CARGO_TARGET_DIR/release/stancelib).
build:
	$(CARGO) build --release

## Install the binary into ~/.cargo/bin (on the PATH of a rustup install).
install:
	$(CARGO) install --path . --locked

doc:
	$(CARGO) doc --no-deps

## Re-generate fixtures/bvh from the project's own generator (see fixtures/README.md).
SYNTH = $(CARGO) run --release -- synth --seed 1
fixtures:
	$(SYNTH) --motion run --rate 120 --duration 1.5 --unit m --up Y --out fixtures/bvh/run_120hz_m_yup.bvh
	$(SYNTH) --motion run --rate 60 --duration 1.5 --unit cm --up Z --out fixtures/bvh/run_60hz_cm_zup.bvh
	$(SYNTH) --motion run --rate 30 --duration 2.0 --unit in --up Y --out fixtures/bvh/run_30hz_in_yup.bvh
	$(SYNTH) --motion jump --rate 120 --duration 2.2 --unit cmu --up Y --out fixtures/bvh/jump_120hz_cmu_yup.bvh
	$(SYNTH) --motion jump --rate 100 --duration 2.2 --unit m --up Z --out fixtures/bvh/jump_100hz_m_zup.bvh
