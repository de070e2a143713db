# One command each: `make demo` and `make test` create .venv and install on
# first use; re-running them reinstalls only when pyproject.toml or
# constraints.txt changed.  constraints.txt pins every package the results
# depend on (CadQuery/OCP tessellation, numpy, scipy, numba, qhull).
PY      ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
STAMP   := $(VENV)/.installed
DATA    ?= ../shared/datasets

.PHONY: install demo demo-paper test check bench bench-compare lint fuzz fuzz-merge lock clean

install: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[test]'
	touch $(STAMP)

# the main job end to end: sample a sharp CAD shape (a block with two
# through-holes, genus 2) like a line scanner, reconstruct it, and check the
# result against the shape's own ground truth
DEMO_SHAPE ?= block_two_holes

demo: $(STAMP)
	mkdir -p out
	$(BIN)/sr33 sample $(DEMO_SHAPE) -o out/demo_points.ply --truth out/demo_truth.ply --meta out/demo_meta.json
	$(BIN)/sr33 reconstruct out/demo_points.ply -k 33 -o out/demo_mesh.ply --save out/demo.npz
	$(BIN)/sr33 validate out/demo_mesh.ply --truth out/demo_truth.ply --points out/demo_points.ply
	$(BIN)/sr33 view out/demo.npz --truth out/demo_truth.ply --screenshot out/demo.png

demo-paper: $(STAMP)
	mkdir -p out
	$(BIN)/sr33 reconstruct $(DATA)/paper/large/cube.obj -k 33 -o out/cube.ply

# the suite a developer runs often (what .ci/run calls): ruff, then every
# test not marked slow, on two workers
test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/python -m pytest -q -n 2 --dist loadfile -m "not slow"

# the slow checks: the geodesic Condition III of every library shape's
# default sampling, every default sampling's contract and reconstruction,
# 20k-point samplings (see the README for their times); all in one file, so
# spread by shape (xdist groups), not by file
check: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup -m slow

bench: $(STAMP)
	$(BIN)/python bench/run.py --data $(DATA) --out out/bench.json
	$(BIN)/python bench/samplers_report.py --out out/samplers.json
	$(BIN)/python bench/validators_bench.py
	$(BIN)/python bench/perturbation.py --out out/perturbation.json

# the installed versions, written back as the pins (after a deliberate upgrade)
lock: $(STAMP)
	head -3 constraints.txt > constraints.new
	$(BIN)/python -m pip freeze --exclude-editable | sort >> constraints.new
	mv constraints.new constraints.txt

# the deep profile of the fuzz targets (file readers over mutated bytes,
# messy point arrays; over 10,000 inputs) and of the properties, the
# generated-model property at GENERATED_PER_CLASS (125) models per feature
# class (1,000 models: hours); one file alone: make fuzz FUZZ=tests/test_fuzz.py;
# a survey of the generated models (no shrinking, failures listed with their
# recipes, every class's shares): make fuzz FUZZ=tests/test_generated.py
# FUZZ_SURVEY=1 GENERATED_PER_CLASS=4; FUZZ_SEED=N draws the same models
# again (a survey before and after a change, on the same models);
# FUZZ_JOBS=2 spreads the tests over two processes (pytest-xdist);
# FUZZ_OUT=run.json saves the run's report, and make fuzz-merge
# FUZZ_REPORTS="a.json b.json" prints saved runs (other seeds) as one report
FUZZ ?= tests/test_fuzz.py tests/test_properties.py tests/test_generated.py
FUZZ_SURVEY ?= 0
GENERATED_PER_CLASS ?= 125
FUZZ_SEED ?=
FUZZ_JOBS ?=
FUZZ_OUT ?=
fuzz: $(STAMP)
	HYPOTHESIS_PROFILE=deep FUZZ_REPORT=1 FUZZ_SURVEY=$(FUZZ_SURVEY) \
	FUZZ_REPORT_JSON=$(FUZZ_OUT) \
	GENERATED_PER_CLASS=$(GENERATED_PER_CLASS) \
	$(BIN)/python -m pytest -q -p no:cacheprovider \
	$(if $(FUZZ_JOBS),-n $(FUZZ_JOBS) --dist load) \
	$(if $(FUZZ_SEED),--hypothesis-seed=$(FUZZ_SEED)) $(FUZZ)

FUZZ_REPORTS ?=
fuzz-merge: $(STAMP)
	$(BIN)/python -m tests.fuzzstats $(FUZZ_REPORTS)

# the optional comparison (Open3D ball pivoting and Poisson, CGAL advancing
# front); Open3D's wheel needs the system library libusb-1.0
bench-compare: $(STAMP)
	dpkg -s libusb-1.0-0 >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -qq libusb-1.0-0)
	$(BIN)/python -m pip install --quiet -e '.[test,compare]'
	$(BIN)/python bench/run.py --data $(DATA) --out out/bench.json --compare

lint: $(STAMP)
	$(BIN)/ruff check .

clean:
	rm -rf $(VENV) out .pytest_cache .hypothesis
