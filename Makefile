# stancelib: the two commands a newcomer needs are `make demo` and `make test`.
CARGO ?= cargo

.PHONY: demo test golden lint bench nightly build install doc fixtures fuzz spark-demo

DEMO_EDITS = out/demo/edits
RUN_CLIP = fixtures/bvh/run_120hz_m_yup.bvh
JUMP_CLIP = fixtures/bvh/jump_120hz_cmu_yup.bvh
## Run the main job on the bundled fixtures (pipelines/demo.toml); tables go to out/demo/,
## edited runs and a jump (BVH + plan + PNG) to out/demo/edits/.
demo:
	$(CARGO) run --release -- run pipelines/demo.toml
	@# Edited motion (issue 14): runs at 2, 3, 4 m/s and a jump 20 % higher than recorded.
	@# Each prints its verdict; exit 1 (frames off the plan or posture outside the recording)
	@# and 3 (infeasible, written with --allow-infeasible) still write the motion.
	mkdir -p $(DEMO_EDITS)
	for v in 2 3 4; do \
		$(CARGO) run --release --quiet -- edit run --lib out/demo --speed $$v --source $(RUN_CLIP) \
			--stance run_120hz_m_yup:R:51 --allow-infeasible --out $(DEMO_EDITS)/run_$${v}mps.bvh \
			|| { c=$$?; test $$c -eq 1 -o $$c -eq 3; }; \
	done
	$(CARGO) run --release --quiet -- edit jump --lib out/demo --height-scale 1.2 --source $(JUMP_CLIP) \
		--pair jump_120hz_cmu_yup:LR:42:jump_120hz_cmu_yup:LR:150 --allow-infeasible \
		--out $(DEMO_EDITS)/jump_120pct.bvh || { c=$$?; test $$c -eq 1 -o $$c -eq 3; }

## Every test: unit, integration (real clips from ../shared/data when present) and doc tests.
test:
	$(CARGO) test --all-targets
	$(CARGO) test --doc

## Rewrite fixtures/golden/demo/ (the demo job's outputs that `make test` compares byte for
## byte) from the current build; review `git diff fixtures/golden` before committing it.
golden:
	UPDATE_GOLDEN=1 $(CARGO) test --test integration golden

## Formatting, clippy and the API docs' links, warnings as errors.
lint:
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --no-deps --lib

## Mutation fuzzer of the reader and ingest for STANCELIB_FUZZ_SECS seconds (default 300);
## failing inputs are saved under fixtures/regressions/ (replayed by `make test`).
STANCELIB_FUZZ_SECS ?= 300
fuzz:
	STANCELIB_FUZZ_SECS=$(STANCELIB_FUZZ_SECS) $(CARGO) test --test integration \
		safety_inputs::mutation_fuzz_for_a_time_budget -- --ignored --nocapture

## Criterion benchmarks: parse, FK+COM, ingest (stages); `frames` and `build` of the bulk
## set against the parse limit of the same files, 2 and 1 threads (ingest_ratio, prints the
## ratios); peak RSS and wall of `build` on the bulk set and a 25× replica of it (scale,
## issue 16; needs about 25 × the set's size in the temporary folder); full library build,
## 10k stances
## (library); candidate evaluations and the 200 × 200 jump map (queries); 2PAC H-rep,
## transition QP and 10-phase trajectory (twopac); 1 s of edited motion at 120 Hz (edit).
## They run in the `profiling` profile (release code with line tables, for perf).
bench:
	$(CARGO) bench --profile profiling --bench stages
	$(CARGO) bench --profile profiling --bench ingest_ratio
	$(CARGO) bench --profile profiling --bench scale
	$(CARGO) bench --profile profiling --bench library
	$(CARGO) bench --profile profiling --bench queries
	$(CARGO) bench --profile profiling --bench twopac
	$(CARGO) bench --profile profiling --bench edit

## The nightly job over ../shared/data (pipelines/nightly.toml).
nightly:
	$(CARGO) run --release -- run pipelines/nightly.toml

## The release binary: target/release/stancelib (or $$CARGO_TARGET_DIR/release/stancelib).
build:

## The bulk CMU set built by Apache Spark in local mode (8 shards on local[2], then merge) into
## out/spark-demo/; needs Java 17 and `python3 -m pip install pyspark` (pipelines/spark/).
STANCELIB_BIN ?= $${CARGO_TARGET_DIR:-target}/release/stancelib
spark-demo:
	$(CARGO) build --release
	python3 pipelines/spark/stancelib_spark.py --master 'local[2]' --shards 8 \
		--stancelib $(STANCELIB_BIN) --out out/spark-demo ../shared/data/bvh-bulk/cmu

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
