"""Suite-wide test settings.

Hypothesis runs derandomized: the same examples on every run and every machine, so a red CI is a
real regression and never a lucky draw (docs/cosim.md: determinism; tests never depend on the
machine). Explore with fresh randomness locally by `HYPOTHESIS_PROFILE=explore pytest ...`.
The fast suite (the run that deselects the slow tests: ``make test``, a bare pytest) loads the
``fast`` profile, a share of each property test's examples (tests/property_examples.py); a run
that includes the slow tests (``make test-all``) loads ``ci``, every example.
"""

import functools
import json
import os
import shutil
import sys
from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
# the fast profile's examples, per 100 of the full one's (Hypothesis' default max_examples):
# a count n of tests/property_examples.py's examples(n) runs n * FAST_SHARE / 100 of them
FAST_SHARE = 40
settings.register_profile("fast", settings.get_profile("ci"), max_examples=FAST_SHARE)
settings.register_profile("explore", deadline=None)


def _editable_tree_misses() -> list[str]:
    """Modules of the checkout that the editable install's tree of links lacks (a module added
    since ``make venv``; the Makefile explains the tree). Empty for any other install."""
    import tomllib

    from mobigrasp.resources import data_dir

    installed = data_dir("mobigrasp")
    root = Path(__file__).resolve().parents[1]
    if "__editable__" not in str(installed) or not (root / "pyproject.toml").is_file():
        return []  # not the clone's editable install, or this file copied out of the clone
    mapping = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    missing = []
    for package, folder in mapping["package-dir"].items():
        target = installed.joinpath(*package.split(".")[1:])
        missing += [str(Path(folder) / py.relative_to(root / folder))
                    for py in (root / folder).rglob("*.py")
                    if not (target / py.relative_to(root / folder)).exists()]
    return missing


def pytest_configure(config):
    # before the test modules are imported: their examples(n) read the profile
    fast = config.getoption("markexpr", "").strip() == "not slow"
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "fast" if fast else "ci"))
    if missing := _editable_tree_misses():
        pytest.exit(f"the editable install lacks {', '.join(sorted(missing)[:5])}: run `make venv`",
                    returncode=4)


# The test files that take longest (CPU s of each in a fast-suite run, measured 2026-12-07),
# longest first, ahead of the others: make test's workers take whole files (--dist loadfile) in
# collection order (--no-loadscope-reorder), so the long ones start early, the short ones fill
# in at the end and the two workers finish together.
LONG_FILES_FIRST = (
    "unit/calib/test_calib_arm.py",  # ~24: the emulated ARM920T kernels on whole frames
    "unit/calib/test_calib_program.py",  # ~21: the C program's replays under unicorn
    "unit/calib/test_hostc_arm.py",  # ~19 on a cold cache (its builds), ~1 warm
    "unit/hostc/test_hostc_builds.py",  # ~17 on a cold cache (its builds), ~0 warm
    "unit/tools/test_bench_loop.py",  # ~8
    "unit/hostc/test_hostc_task001.py",  # ~8
    "unit/services/test_mcap_out.py",  # ~7 (the short_runs fixture's runs)
    "system/test_sim_serve.py",  # ~6
    "unit/hostc/test_hostc_task.py",  # ~6
    "unit/calib/test_calib_native.py",  # ~5
    "unit/host/test_host_bounded_state.py",  # ~5
    "unit/hostc/test_hostc_task000.py",  # ~5
    "system/test_planning_001_closed_loop.py",  # ~4
    "unit/hostc/test_hostc_replan.py",  # ~4
    "unit/services/test_plots_readable.py",  # ~4
    "system/test_001_short_wall.py",  # ~4
)


def pytest_collection_modifyitems(config, items):
    rank = {name: k for k, name in enumerate(LONG_FILES_FIRST)}

    def order(item) -> int:  # node ids start at the repository's root
        return rank.get(item.nodeid.split("::")[0].removeprefix("tests/"), len(rank))

    items.sort(key=order)  # stable: the other files, and the tests in a file, keep their order


# Modules marked ``pytestmark = pytest.mark.both_mcus`` run every test on each MCU backend: the
# module's ``Mcu`` is the Python model for ``python``, the C firmware for ``native`` and, where
# the module is also marked ``simavr``, the avr-gcc ELF under simavr, started up before the
# test's first byte. A test that reads what only the Python model exposes skips ``simavr`` with
# ``@pytest.mark.not_on("simavr", reason)``; ``slow_on_simavr`` marks its simavr variant slow.
MCU_BACKENDS_UNDER_TEST = ("python", "native", "simavr")


def pytest_generate_tests(metafunc):
    if metafunc.definition.get_closest_marker("both_mcus") is None:
        return
    names = ["python", "native"]
    if metafunc.definition.get_closest_marker("simavr") is not None:
        names.append("simavr")
    params = []
    for name in names:
        marks = []
        skip = [mk for mk in metafunc.definition.iter_markers("not_on") if mk.args[0] == name]
        if skip:
            marks.append(pytest.mark.skip(reason=f"{name}: {skip[0].args[1]}"))
        if name == "simavr" and metafunc.definition.get_closest_marker("slow_on_simavr"):
            marks.append(pytest.mark.slow)
        params.append(pytest.param(name, marks=marks, id=name))
    metafunc.fixturenames.append("mcu_backend")
    metafunc.parametrize("mcu_backend", params, indirect=True)


def booted_simavr_mcu(config=None):
    """The ELF under simavr, advanced until its start-up is over (main loop begun, ~2.2 ms
    after reset, docs/firmware.md): the Python models take no time for it, so a test written
    for them talks from its first line. Times in such a test are relative to the end of the
    start-up."""
    from mobigrasp.mcu_sim.simavr.mcu import SimavrMcu

    mcu = SimavrMcu(config)
    mcu.run_until_booted()
    return mcu


@pytest.fixture
def mcu_backend(request):
    return request.param


@pytest.fixture(autouse=True)
def _mcu_of_the_backend(request, monkeypatch):
    # a fixture appended to fixturenames in pytest_generate_tests is parametrized but never set
    # up, so the module's Mcu is swapped here, from the test's parameters
    callspec = getattr(request.node, "callspec", None)
    backend = callspec.params.get("mcu_backend") if callspec is not None else None
    if backend == "native":
        from mobigrasp.mcu_sim.native.mcu import NativeMcu

        monkeypatch.setattr(request.module, "Mcu", NativeMcu)
    elif backend == "simavr":
        monkeypatch.setattr(request.module, "Mcu", booted_simavr_mcu)


# three short in-process runs (one per method) whose run folders several output tests read
SHORT_RUNS = {"paper000-exp1": None, "paper001-sim1": 8.0, "paper002-marker": 8.0}


def made_once_per_run(tmp_path_factory, name: str, make) -> Path:
    """The folder ``name`` that ``make(folder)`` fills, once per test run: the workers of a
    parallel run (pytest-xdist, ``make test``) share the one the first of them makes, the
    others wait for it on a lock (src/mobigrasp/cbuild.py's build_once) rather than make their
    own; the tests only read it."""
    from mobigrasp import cbuild

    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        folder = tmp_path_factory.mktemp(name)
        make(folder)
        return folder
    root = tmp_path_factory.getbasetemp().parent  # the run's, above each worker's own
    folder, done = root / name, root / f"{name}.done"

    def build() -> None:
        shutil.rmtree(folder, ignore_errors=True)  # what a worker that failed left
        folder.mkdir()
        make(folder)
        done.touch()

    cbuild.build_once(folder, done.exists, build)
    return folder


@pytest.fixture(scope="session")
def short_runs(tmp_path_factory):
    """{scenario: run folder} of SHORT_RUNS (time limits in simulated s; None: the scenario's)."""
    from mobigrasp.services.run_job import RunOptions, execute

    def make(root: Path) -> None:
        for name, limit_s in SHORT_RUNS.items():
            summary, _ = execute(RunOptions(scenario=name, transport="inproc", out=root / name,
                                            progress=False, time_limit_s=limit_s))
            assert_no_false_claim(summary)

    root = made_once_per_run(tmp_path_factory, "short-runs", make)
    return {name: root / name for name in SHORT_RUNS}


@pytest.fixture(scope="session")
def marker_slice(tmp_path_factory):
    """The detector corpus (mobigrasp.services.corpus) of the first 4 s of paper002-marker: the
    double cross searched for, then the cylinder."""
    from mobigrasp.services.corpus import record

    return made_once_per_run(tmp_path_factory, "marker", lambda folder: record(
        folder, ["paper002-marker"], time_limit_s=4.0))


@pytest.fixture(scope="session")
def exp1_corpus(tmp_path_factory):
    """The detector corpus of the whole of paper000-exp1: the dual plus and the spoke searched
    for, found and lost (the C and the emulated ARM kernels are checked on slices of it)."""
    from mobigrasp.services.corpus import record

    return made_once_per_run(tmp_path_factory, "exp1-corpus",
                             lambda folder: record(folder, ["paper000-exp1"]))


@pytest.fixture
def close_start_done(tmp_path):
    """``run(method, seed)``: the generator v3 scene of ``method`` and ``seed``, its target
    0.3-0.5 m from the start, run in process to DONE without a contact; its trace's events and
    its ``back_off`` detail events (tests/system/test_00*_close_start.py)."""
    import math

    from mobigrasp.services.random_scenarios import random_scenario
    from mobigrasp.services.run_job import RunOptions, execute

    def run(method: str, seed: int) -> tuple[list, list]:
        scenario = random_scenario(method, seed, "v3")
        assert math.hypot(scenario.target.x_m, scenario.target.y_m) < 0.5  # a close start
        out = tmp_path / f"{method}-{seed}"
        summary, code = execute(RunOptions(scenario=f"random-v3-{method}-{seed}",
                                           scenario_obj=scenario, transport="inproc", out=out,
                                           plots=False, mcap=False, progress=False))
        assert summary["success"] and code == 0, (summary["task_state"], summary["end_reason"])
        assert summary["contacts"] == 0
        events = [json.loads(line) for line in (out / "trace.jsonl").open()]
        return events, [e for e in events if e.get("ev") == "detail" and "back_off" in e]

    return run


def assert_no_false_claim(summary: dict) -> None:
    """A run that ended DONE without the object in the gripper fails the test (docs/task.md)."""
    assert not summary.get("false_claim"), (
        f"{summary.get('scenario')} seed {summary.get('seed')}: false claim of success "
        f"({summary.get('task_state')}, {summary.get('end_reason')}, grasped "
        f"{summary.get('grasped')})")


def checked_execute(execute):
    """``execute`` (services.run_job) that fails on a run whose summary is a false claim."""

    @functools.wraps(execute)
    def checked(*args, **kwargs):
        summary, code = execute(*args, **kwargs)
        assert_no_false_claim(summary)
        return summary, code

    return checked


def false_claims_under(folder: Path) -> list[str]:
    """Every summary.json under ``folder`` that is a false claim (a run in a subprocess, a
    worker process or a Dask worker that the wrapped ``execute`` of this process never saw)."""
    found = []
    for path in sorted(Path(folder).rglob("summary.json")):
        try:
            summary = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue  # a torn or deliberately broken summary is not a claim
        if isinstance(summary, dict) and summary.get("false_claim"):
            found.append(f"{path}: {summary.get('scenario')} seed {summary.get('seed')} ended "
                         f"{summary.get('task_state')} without the object")
    return found


_TESTS = Path(__file__).resolve().parent


@pytest.fixture(autouse=True)
def _no_false_claim(request, monkeypatch):
    """Every test that runs a scenario fails on a false claim: services.run_job.execute is
    checked in this process (also where a test or helper module imported it by name), and the
    run folders under the test's tmp_path are read after it for runs made elsewhere."""
    from mobigrasp.services import run_job

    real = run_job.execute
    checked = checked_execute(real)
    monkeypatch.setattr(run_job, "execute", checked)
    for module in list(sys.modules.values()):
        # the name first (from the module's own namespace, no lazy __getattr__): resolving
        # the path of every loaded module made this fixture the suite's costliest
        if getattr(module, "__dict__", {}).get("execute") is not real:
            continue
        where = getattr(module, "__file__", None)
        if where and _TESTS in Path(where).resolve().parents:
            monkeypatch.setattr(module, "execute", checked)
    yield
    tmp = request.node.funcargs.get("tmp_path")
    if tmp is not None:
        claims = false_claims_under(tmp)
        assert not claims, "false claim of success:\n" + "\n".join(claims)


# --- the hostc replay tests' shared recordings (tests/unit/hostc) ---------------------------------
# The shipped scenarios several hostc replay tests record: each run once a session, with every
# test's recorder attached at once (each fills its own list and only reads the run), instead of
# once per test file. The replays only read what was recorded. (Here, not in a conftest of
# tests/unit/hostc: a second conftest module would take the name ``conftest`` that tests import.)
def _paper001() -> dict:
    from test_hostc_plan001 import record_plans
    from test_hostc_replan import record_replans
    from test_hostc_task001 import record001_steps

    return {"plans": record_plans, "replans": record_replans, "task": record001_steps}


def _paper002_marker() -> dict:
    from test_hostc_task import record002, record002_approach
    from test_hostc_task_states import record_steps

    return {"calls": record002, "approach": record002_approach, "steps": record_steps}


def _paper000_exp1() -> dict:
    from test_hostc_task000 import record000
    from test_hostc_task_states import record_steps

    return {"calls": record000, "steps": record_steps}


# scenario -> its recorders by name
SHARED = {"paper000-exp1": _paper000_exp1, "paper001-sim1": _paper001,
          "paper001-sim2": _paper001, "paper002-marker": _paper002_marker}


@pytest.fixture(scope="session")
def shared_recording(tmp_path_factory):
    """``get(scenario, name)``: what recorder ``name`` recorded in the session's one run of
    ``scenario`` (made at the first ``get``)."""
    from test_hostc_task import recorded_runs

    runs: dict[str, dict[str, list]] = {}

    def get(scenario: str, name: str) -> list:
        if scenario not in runs:
            runs[scenario] = recorded_runs(tmp_path_factory.mktemp(scenario), scenario,
                                           SHARED[scenario]())
        return runs[scenario][name]
    return get
