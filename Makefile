# The README's contract: `make demo` runs the main job, `make test` runs the tests.
# Both create .venv and install what they need; `make venv` only does that and is a no-op when
# pyproject.toml has not changed since the last install.
#
# The interpreter: the first of these that is Python >= 3.11 with venv. The distribution's own
# comes first: a run is bound by the interpreter, and Debian's python3.11 (built with
# profile-guided and link-time optimisation, libpython linked in) ran paper000-exp1 over the pty
# 13 % faster than a default source build of 3.11 (pyenv's), with the same trace (docs/cosim.md,
# "Measured"). `make PYTHON=/path/to/python3 ...` chooses another.
ifndef PYTHON
PYTHON := $(shell for p in /usr/bin/python3.11 /usr/bin/python3 python3.11 python3; do \
	  if command -v $$p >/dev/null 2>&1 && $$p -c 'import sys, venv, ensurepip; \
	    sys.exit(sys.version_info < (3, 11))' >/dev/null 2>&1; then command -v $$p; break; fi; \
	done)
endif
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# which interpreter built .venv: a venv of another one is made again
BASE := $(VENV)/.base-python

.PHONY: venv test test-all lint ruff-tracked demo clean browser firmware toolchains FORCE

venv: $(STAMP)

$(BASE): FORCE
	@test -n "$(PYTHON)" || { echo "make: no Python >= 3.11 with venv found" >&2; exit 1; }
	@if [ "$$(cat $@ 2>/dev/null)" != "$(PYTHON)" ]; then \
	  if [ -e $(VENV) ]; then echo "make: .venv is rebuilt with $(PYTHON)"; fi; \
	  rm -rf $(VENV) && mkdir -p $(VENV) && echo "$(PYTHON)" > $@; fi

# The editable install is a tree of links (setuptools' strict editable mode, in build/): real
# folders with one link per file, so import-linter sees every module of the package (a wheel's
# layout, docs/architecture.md). A module added or removed needs the tree made again: the stamp
# depends on the package's folders, whose times change when an entry does, so `make venv` and
# `make test` redo it (tests/conftest.py stops a bare pytest that misses a module and says so).
PKG_DIRS := $(shell find src protocol link host mcu_sim cosim drivers calib services tools \
	scenarios firmware hostc -type d -not -name __pycache__ -not -path '*/build*' 2>/dev/null)

$(STAMP): pyproject.toml $(BASE) $(PKG_DIRS)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade "pip>=23"
	$(BIN)/python -m pip install --quiet -e '.[sim,plots,cluster,dev]' \
	  --config-settings editable_mode=strict
	@touch $(STAMP)

# ruff on the repository's tracked files only: an untracked folder in a clone is the user's
# (outside a git checkout: every file, as `ruff check .`)
RUFF := $(BIN)/ruff
lint: venv
	$(BIN)/lint-imports
	@$(MAKE) --no-print-directory ruff-tracked RUFF=$(RUFF)

ruff-tracked:
	@if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then \
	  git ls-files -z -- '*.py' | xargs -0 -r $(RUFF) check --force-exclude; \
	else $(RUFF) check .; fi

# Debian packages of the C parts: the avr-gcc firmware, libsimavr (the simavr MCU backend) and the
# ARM920T toolchain (mobigrasp calibrate); installed with apt-get when missing and apt-get can run
DEB_TOOLS := gcc-avr avr-libc simavr libsimavr-dev gcc-arm-none-eabi
toolchains:
	@missing=""; for p in $(DEB_TOOLS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -z "$$missing" ]; then exit 0; fi; \
	if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "make: installing$$missing with apt-get"; \
	  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; } \
	    || echo "make: apt-get could not install$$missing" >&2; \
	else echo "make: missing$$missing and apt-get cannot run here" >&2; fi

# the fast suite, then the wheel installed outside the clone (slow: a build and five runs)
test: lint toolchains
	$(BIN)/python -m pytest -q
	$(BIN)/python -m pytest -q -m slow tests/system/test_wheel_install.py

# the report's browser test (slow) renders it in Debian's chromium: installed when missing
browser:
	@command -v chromium >/dev/null 2>&1 || { apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; }

test-all: lint toolchains browser
	$(BIN)/python -m pytest -q -m "slow or not slow"

# The ATmega128 firmware with avr-gcc: firmware/build/mobigrasp-avr.elf and .hex, then its size
# (avr-size -C). gcc-avr and avr-libc are installed with apt-get when avr-gcc is missing.
firmware:
	@command -v avr-gcc >/dev/null 2>&1 || { \
	  echo "make firmware: avr-gcc missing, installing gcc-avr avr-libc with apt-get"; \
	  apt-get update && apt-get install -y gcc-avr avr-libc; }
	$(MAKE) -C firmware

demo: venv
	$(BIN)/mobigrasp demo

clean:
	rm -rf $(VENV) bench-results runs firmware/build build
