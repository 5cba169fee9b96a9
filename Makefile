# Quick start (fresh machine with python3, pip and make):
#   make demo   -> installs seisrack into .venv and reproduces the paper (out/paper)
#   make test   -> installs seisrack with test extras into .venv and runs the whole suite
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test lint bench clean install

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[all,test]'
	$(BIN)/python -m seisrack._warmup
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/seisrack paper --out out/paper

test: $(STAMP)
	# the HTML report's browser test drives Debian's chromium (about 25 s to install here), and
	# the OpenSees cross-checks need OpenSeesPy (the bench extra) with Debian's BLAS/LAPACK
	if command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] && { ! command -v chromium \
	   >/dev/null || ! dpkg -s libblas3 liblapack3 >/dev/null 2>&1; }; then \
	   apt-get update -qq && apt-get install -y -qq chromium libblas3 liblapack3; fi
	$(BIN)/python -m pip install --quiet -e '.[bench]'
	$(BIN)/python -m ruff check src tests benchmarks
	$(BIN)/python -m pytest -n 2 -q tests

lint: $(STAMP)
	$(BIN)/python -m ruff check src tests benchmarks

bench: $(STAMP)
	# OpenSeesPy needs the system BLAS/LAPACK (Debian packages), installed here when possible
	if command -v apt-get >/dev/null && [ "$$(id -u)" = 0 ] && \
	   ! dpkg -s libblas3 liblapack3 >/dev/null 2>&1; then \
	   apt-get update -qq && apt-get install -y -qq libblas3 liblapack3; fi
	$(BIN)/python -m pip install --quiet -e '.[bench]'
	$(BIN)/python benchmarks/scale.py
	$(BIN)/python benchmarks/engine.py
	$(BIN)/python benchmarks/motion.py
	$(BIN)/python benchmarks/rack_vs_opensees.py

clean:
	rm -rf $(VENV) out .pytest_cache
