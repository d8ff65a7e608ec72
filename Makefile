# Two commands on a fresh machine: `make demo` and `make test`.
# Both create .venv and install pin_susp into it when needed.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
DEMO_DIR ?= demo_output
GEOMETRIES := $(shell grep -l '^hardpoints:' examples/*.yaml | xargs grep -L '^scope: axle')

.PHONY: demo test fuzz drake bench urdf lint format clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	$(BIN)/python -m compileall -q pin_susp  # start-up: read even where bytecode is not written
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/pin-susp demo -o $(DEMO_DIR)

# The suite on TEST_WORKERS processes (pytest-xdist; `make test TEST_WORKERS=0` runs it in
# one). worksteal: each worker takes a contiguous half of the tests (a module's shared
# fixtures computed once, mostly) and one that runs dry takes half of what the other has
# left. pytest exits 5 when it collects no test: that is a failure here too.
TEST_WORKERS ?= 2
test: $(STAMP)
	@$(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist worksteal; status=$$?; \
	if [ $$status -eq 5 ]; then echo "make test: pytest collected no tests" >&2; fi; \
	exit $$status

# Property-based fuzzing of the command line (tests/test_fuzz.py): 10 000 random inputs —
# corners and axles of every mechanism through every command that takes a geometry (sweep,
# loads, setup, sensitivity, urdf, mjcf, draw, validate, tiny studies and their --resume),
# CSV, Parquet and streamed outputs, degenerate linkages — a new seed each run (printed;
# PIN_SUSP_FUZZ_SEED=N repeats it), then the counts per exit code, command and mechanism.
# PIN_SUSP_FUZZ_FINDINGS=DIR saves each failing input as files.
fuzz: $(STAMP)
	PIN_SUSP_FUZZ_EXAMPLES=$${PIN_SUSP_FUZZ_EXAMPLES:-10000} \
	PIN_SUSP_FUZZ_SEED=$${PIN_SUSP_FUZZ_SEED:-random} \
	$(BIN)/python -m pytest -q -s tests/test_fuzz.py -k holds

# Drake against pin_susp on every example with every sweep it takes, every step: each
# corner and the axle, and both cars with every vehicle sweep (tests/test_validate_drake.py;
# `make test` runs a slice of four, and short sweeps of both cars in
# tests/test_vehicle_robotics.py).
drake: $(STAMP)
	PIN_SUSP_DRAKE_ALL=1 $(BIN)/python -m pytest -q tests/test_validate_drake.py

# Speed figures against baselines run in the same process (see README, Performance).
bench: $(STAMP)
	$(BIN)/python benchmarks/bench_sweep.py --json benchmarks/last_run.json
	$(BIN)/python benchmarks/bench_study.py --full --json benchmarks/last_study_run.json
	$(BIN)/python benchmarks/bench_validate.py
	$(BIN)/python benchmarks/bench_attitude.py --json benchmarks/last_attitude_run.json
	$(BIN)/python benchmarks/bench_kc.py

# Regenerate urdf/ from examples/ (a test fails when they differ).
urdf: $(STAMP)
	@for g in $(GEOMETRIES); do \
		$(BIN)/pin-susp urdf $$g -o urdf/$$(basename $$g .yaml).urdf; \
	done

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

clean:
	rm -rf $(VENV) $(DEMO_DIR) .pytest_cache .ruff_cache
