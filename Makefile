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

.PHONY: venv test test-all lint ruff-tracked demo clean browser rerun firmware toolchains hostc hostc-arm \
	arm-tools FORCE

venv: $(STAMP)

$(BASE): FORCE
	@test -n "$(PYTHON)" || { echo "make: no Python >= 3.11 with venv found" >&2; exit 1; }
	@if [ "$$(cat $@ 2>/dev/null)" != "$(PYTHON)" ]; then \
	  if [ -e $(VENV) ]; then echo "make: .venv is rebuilt with $(PYTHON)"; fi; \
	  rm -rf $(VENV) && mkdir -p $(VENV) && echo "$(PYTHON)" > $@; fi

# The editable install is a tree of links (setuptools' strict editable mode, in build/): real
# folders with one link per file, so import-linter sees every module of the package (a wheel's
# layout, docs/architecture.md). A file added or removed needs the tree made again: the stamp
# depends on the list of the package's files, so `make venv` and `make test` redo it
# (tests/conftest.py stops a bare pytest that misses a module and says so).
PKG_ROOTS := src protocol link host mcu_sim cosim drivers calib services tools testing scenarios \
	firmware hostc
PKG_LIST := $(VENV)/.package-files

$(PKG_LIST): FORCE
	@mkdir -p $(VENV)
	@find $(PKG_ROOTS) -type f -not -path '*/__pycache__/*' -not -path '*/build/*' 2>/dev/null \
	  | LC_ALL=C sort > $@.new
	@if cmp -s $@.new $@; then rm $@.new; else mv $@.new $@; fi

$(STAMP): pyproject.toml $(BASE) $(PKG_LIST)
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

# Debian packages of the C parts: the avr-gcc firmware, libsimavr (the simavr MCU backend), the
# ARM920T toolchain (mobigrasp calibrate, the host's ARM build), qemu-user (that build's ARMv4T
# checks) and clang (the fuzzers); installed with apt-get when missing and apt-get can run
DEB_TOOLS := gcc-avr avr-libc simavr libsimavr-dev gcc-arm-none-eabi qemu-user clang
ARM_TOOLS := gcc-arm-none-eabi qemu-user
# $(call deb_install,PACKAGES): apt-get install those of PACKAGES that are missing
define deb_install
@missing=""; for p in $(1); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
if [ -z "$$missing" ]; then exit 0; fi; \
if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
  echo "make: installing$$missing with apt-get"; \
  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; } \
    || echo "make: apt-get could not install$$missing" >&2; \
else echo "make: missing$$missing and apt-get cannot run here" >&2; fi
endef
toolchains:
	$(call deb_install,$(DEB_TOOLS))
arm-tools:
	$(call deb_install,$(ARM_TOOLS))

# The C host for the S3C2440's ARM920T (ARMv4T), docs/porting.md. Every hostc/*.c is portable
# except the native-only *_posix.c, and so is the protocol codec the two boards share
# (firmware/protocol/); hostc/arm/ holds the board's start-up code, its system calls
# (sys_arm.c) and the few C library functions. No C library is linked (Debian's armel one is
# ARMv5TE): libgcc only, whose default multilib is ARMv4T (division and soft-float).
HOSTC_OUT ?= build/hostc
ARM_CC := arm-none-eabi-gcc
ARM_CFLAGS := -mcpu=arm920t -marm -O2 -std=c99 -ffreestanding -Wall -Wextra -Werror \
	-ffunction-sections -fdata-sections
ARM_LDFLAGS := -nostdlib -static -Wl,--gc-sections -Wl,-Ttext-segment=0x10000 -Wl,-z,noexecstack
HOSTC_PORTABLE := $(sort $(filter-out %_posix.c,$(wildcard hostc/*.c)))
HOSTC_PROTOCOL := $(sort $(wildcard firmware/protocol/*.c))
# the self-test's entry until the host has its own main
HOSTC_ARM_MAIN := $(if $(wildcard hostc/main.c),,hostc/arm/selftest_main.c)
HOSTC_BOARD := $(sort $(filter-out hostc/arm/selftest_main.c,$(wildcard hostc/arm/*.c)))
HOSTC_ARM_SRCS := $(HOSTC_PORTABLE) $(HOSTC_PROTOCOL) $(HOSTC_BOARD) $(HOSTC_ARM_MAIN) \
	hostc/arm/start.S
HOSTC_ARM_ELF := $(HOSTC_OUT)/mobigrasp-host-arm920t.elf
# functions kept in the ELF though the program never calls them (--gc-sections drops them
# otherwise): the calibration builds its ELF with its entries (calib/program.py)
HOSTC_ARM_KEEP ?=
comma := ,

# The static ELF: qemu-arm -cpu ti925t HOSTC_ARM_ELF --self-test runs it here
hostc-arm: arm-tools $(HOSTC_ARM_ELF)
	@arm-none-eabi-size $(HOSTC_ARM_ELF)

$(HOSTC_ARM_ELF): $(HOSTC_ARM_SRCS) $(wildcard hostc/*.h hostc/arm/*.h firmware/protocol/*.h) \
		Makefile
	@mkdir -p $(@D)
	$(ARM_CC) $(ARM_CFLAGS) $(ARM_LDFLAGS) $(addprefix -Wl$(comma)--require-defined=,\
		$(HOSTC_ARM_KEEP)) -Ihostc -Ifirmware/protocol -o $@ $(HOSTC_ARM_SRCS) -lgcc

# The portable modules and the board's (hostc/arm/) as ARM920T objects: text/data/bss per object
# and the worst-case stack of each function (-fstack-usage frames on -fcallgraph-info's graph)
HOSTC_OBJ_DIR := $(HOSTC_OUT)/arm920t
HOSTC_OBJS := $(patsubst hostc/%.c,$(HOSTC_OBJ_DIR)/%.o,$(HOSTC_PORTABLE) $(HOSTC_BOARD)) \
	$(patsubst firmware/protocol/%.c,$(HOSTC_OBJ_DIR)/protocol/%.o,$(HOSTC_PROTOCOL))
hostc: arm-tools venv $(HOSTC_OBJS)
	@arm-none-eabi-size -t $(HOSTC_OBJS)
	@$(BIN)/python -m mobigrasp.tools.hostc_budget $(HOSTC_OBJ_DIR)

$(HOSTC_OBJ_DIR)/%.o: hostc/%.c $(wildcard hostc/*.h hostc/arm/*.h firmware/protocol/*.h) Makefile
	@mkdir -p $(@D)
	$(ARM_CC) $(ARM_CFLAGS) -fstack-usage -fcallgraph-info=su -Ihostc -Ifirmware/protocol -c -o $@ $<

$(HOSTC_OBJ_DIR)/protocol/%.o: firmware/protocol/%.c $(wildcard firmware/protocol/*.h) Makefile
	@mkdir -p $(@D)
	$(ARM_CC) $(ARM_CFLAGS) -fstack-usage -fcallgraph-info=su -Ifirmware/protocol -c -o $@ $<

# the fast suite, then the wheel installed outside the clone (slow: a build and five runs).
# The fast suite runs on TEST_WORKERS processes (pytest-xdist): the machine's cores, at most 2,
# as CI has; a test file stays on one worker (its module fixtures are made once), the session
# fixtures and the C builds in the cache are made once and shared (tests/conftest.py,
# src/mobigrasp/cbuild.py). `make test TEST_WORKERS=0` runs it in this one process.
# The longest test files go first (tests/conftest.py LONG_FILES_FIRST; xdist's own order is by
# the number of tests in a file). PYTHONDONTWRITEBYTECODE is cleared for the suite: pytest keeps
# the test modules it rewrites (assertion rewriting) in __pycache__ only where bytecode may be
# written, and without that every worker rewrites all the test modules again (~5 s of CPU).
TEST_WORKERS ?= $(shell n=$$(nproc 2>/dev/null || echo 1); [ "$$n" -gt 2 ] && n=2; echo $$n)
test: lint toolchains
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile \
	  --no-loadscope-reorder
	$(BIN)/python -m pytest -q -m slow tests/system/test_wheel_install.py

# the report's browser test (slow) renders it in Debian's chromium: installed when missing
browser:
	@command -v chromium >/dev/null 2>&1 || { apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; }

# Rerun's MCAP reader for its slow test: an extra of its own (~650 MB, docs/outputs.md)
rerun: venv
	@$(BIN)/python -c 'import rerun.chunk' 2>/dev/null || \
	  $(BIN)/python -m pip install --quiet -e '.[rerun]' --config-settings editable_mode=strict

test-all: lint toolchains browser rerun
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -q -m "slow or not slow"

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
