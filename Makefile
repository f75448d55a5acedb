# Two commands do everything on a fresh machine: `make run` and `make test`.
# Each creates .venv on first use. torch is pinned to the CPU build before anything else asks for it.
PYTHON ?= python3
# On machines whose pip does not already see a CPU build of torch, point this at one, e.g.
#   make test TORCH_INDEX=https://download.pytorch.org/whl/cpu
TORCH ?= torch==2.13.0
TORCH_INDEX ?=
# The text reader, without its opencv-python requirement: one OpenCV, the headless one
# (pyproject.toml lists its other runtime dependencies).
RAPIDOCR ?= rapidocr-onnxruntime==1.4.4
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test test-fast lint clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet $(TORCH) $(if $(TORCH_INDEX),--index-url $(TORCH_INDEX))
	$(PY) -m pip install --quiet -e ".[dev]"
	$(PY) -m pip install --quiet --no-deps $(RAPIDOCR)
	touch $(STAMP)

run: $(STAMP)
	$(PY) -m f2n_drake.run examples/plan.png --out out/example

test: $(STAMP)
	$(PY) -m pytest -n 2 -q

test-fast: $(STAMP)
	$(PY) -m pytest -n 2 -q -m "not slow and not notebook"

lint: $(STAMP)
	$(VENV)/bin/ruff check .

clean:
	rm -rf $(VENV) out .pytest_cache
