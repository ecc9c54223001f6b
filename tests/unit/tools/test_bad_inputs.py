"""Bad input is exit 2 with one line naming the file (or option) and the key, never a traceback.

One row per case, run through the CLI in process (``mobigrasp.tools.cli.main``); a scenario row
writes a shipped scenario with one value changed. Then hypothesis mutates every key of every
shipped scenario and checks the run command's answer (``run --check`` in the fast suite, a
short real run in the slow one).
"""

from __future__ import annotations

import json
import math
import tomllib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.services.run_job import shipped_scenarios
from mobigrasp.tools.cli import main

SCENARIOS = {p.stem: p for p in shipped_scenarios()}
QUICK = ["--transport", "inproc", "--time-limit-s", "0.1", "--quiet", "--no-plots"]


# --- TOML out (tomllib reads only): every value inline, so any shape of document is written ---

def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string (\uXXXX escapes are TOML too)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_dumps(doc: dict) -> str:
    return "".join(f"{json.dumps(k)} = {_toml_value(v)}\n" for k, v in doc.items())


def shipped(name: str) -> dict:
    return tomllib.loads(SCENARIOS[name].read_text())


def test_toml_writer_round_trips_every_shipped_scenario():
    for name in SCENARIOS:
        assert tomllib.loads(toml_dumps(shipped(name))) == shipped(name)


def mutated(tmp_path: Path, name: str, path: tuple, value: Any) -> Path:
    """The shipped scenario ``name`` with the value at ``path`` (keys and list indices) set."""
    doc = shipped(name)
    node = doc
    for k in path[:-1]:
        node = node.setdefault(k, {}) if isinstance(k, str) else node[k]
    node[path[-1]] = value
    out = tmp_path / f"{name}-mutated.toml"
    out.write_text(toml_dumps(doc))
    return out


# --- the table -------------------------------------------------------------------------------

@dataclass
class Case:
    argv: Callable[[Path, pytest.MonkeyPatch], list[str]]
    names: tuple[str, ...]  # what the one line must name (besides the file: see _file)


def _sc(name: str, path: tuple, value: Any, *extra: str) -> Callable:
    def argv(tmp: Path, mp: pytest.MonkeyPatch) -> list[str]:
        return ["run", str(mutated(tmp, name, path, value))] + QUICK + list(extra)
    return argv


def _raw(data: bytes) -> Callable:
    def argv(tmp: Path, mp: pytest.MonkeyPatch) -> list[str]:
        p = tmp / "raw.toml"
        p.write_bytes(data)
        return ["run", str(p)] + QUICK
    return argv


def _out(make: Callable[[Path, pytest.MonkeyPatch], Path], check: bool = False) -> Callable:
    def argv(tmp: Path, mp: pytest.MonkeyPatch) -> list[str]:
        return (["run", "paper000-exp1", "--out", str(make(tmp, mp))] + QUICK
                + (["--check"] if check else []))
    return argv


def _a_file(tmp: Path, mp) -> Path:
    (tmp / "f").write_text("x")
    return tmp / "f"


def _under_a_file(tmp: Path, mp) -> Path:
    (tmp / "f").write_text("x")
    return tmp / "f" / "run"


def _a_symlink(tmp: Path, mp) -> Path:
    (tmp / "real").mkdir()
    (tmp / "link").symlink_to(tmp / "real")
    return tmp / "link"


def _unwritable(tmp: Path, mp) -> Path:
    # as root a chmod does not stop a write: the refusal the filesystem would give is made here
    target = tmp / "ro" / "run"
    (tmp / "ro").mkdir()
    (tmp / "ro").chmod(0o500)
    real_mkdir = Path.mkdir

    def mkdir(self, *a, **kw):
        if self == target:
            raise PermissionError(13, "Permission denied", str(self))
        return real_mkdir(self, *a, **kw)
    mp.setattr(Path, "mkdir", mkdir)
    return target


def _not_empty(tmp: Path, mp) -> Path:
    (tmp / "mine").mkdir()
    (tmp / "mine" / "summary.json").write_text("{}")
    (tmp / "mine" / "notes.txt").write_text("x")
    return tmp / "mine"


def _foreign_trace(tmp: Path, mp) -> Path:
    """A run folder (its marker lists nothing) holding a trace.jsonl mobigrasp did not write."""
    from mobigrasp.cosim.run_folder import claim_run_folder

    with claim_run_folder(tmp / "run", "x", 1) as held:
        held.prepare()
    (tmp / "run" / "trace.jsonl").write_text("mine\n")
    return tmp / "run"


def _raw_scenario(name: str, tail: str, params: str = "") -> Callable:
    """A shipped scenario's text with ``tail`` appended (a table it has not) and ``params``
    put at the top of its [params] table."""
    def argv(tmp: Path, mp: pytest.MonkeyPatch) -> list[str]:
        text = SCENARIOS[name].read_text()
        if params:
            text = text.replace("[params]\n", f"[params]\n{params}\n", 1)
            assert params in text
        p = tmp / "raw.toml"
        p.write_text(text + "\n" + tail + "\n")
        return ["run", str(p), "--check"]
    return argv


def _host_config(cfg: dict | str) -> Callable:
    def argv(tmp: Path, mp: pytest.MonkeyPatch) -> list[str]:
        p = tmp / "host.json"
        p.write_text(cfg if isinstance(cfg, str) else json.dumps(cfg))
        return ["host", "--port", "/dev/pts/99", "--config", str(p)]
    return argv


def _corpus_of(*names: str) -> Callable:
    """A corpus folder holding ``names`` (no frames): argv of calibrate on it."""
    def make(tmp: Path, mp) -> Path:
        folder = tmp / "corpus"
        folder.mkdir()
        (folder / "corpus.json").write_text(json.dumps({
            "format": "mobigrasp-corpus/1", "frames": [],
            "scenarios": [{"name": n, "seed": 1, "camera": {}, "calls": 0} for n in names]}))
        return folder
    return make


def _fifo(tmp: Path) -> Path:
    import os

    os.mkfifo(tmp / "fifo")
    return tmp / "fifo"


E = "paper000-exp1"
B = "paper001-sim1"  # with obstacles
M = "paper002-cylinder-moving"  # with a path
CASES: dict[str, Case] = {
    "non-utf8 file": Case(_raw(b'[scenario]\nname = "\xff\xfe"\n'), ("raw.toml", "UTF-8")),
    "truncated file": Case(_raw(SCENARIOS[E].read_bytes()[:200]), ("raw.toml",)),
    "not toml": Case(_raw(b"\x00\x01\x02"), ("raw.toml", "TOML")),
    "scenario a folder": Case(lambda t, mp: ["run", str(t)] + QUICK, ()),
    "unknown key": Case(_sc(E, ("robot", "colour"), 3), ("robot.colour", "unknown key")),
    "out a file": Case(_out(_a_file), ("--out",)),
    "out under a file": Case(_out(_under_a_file), ("--out",)),
    "out a symlink": Case(_out(_a_symlink), ("--out", "symbolic link")),
    "out unwritable": Case(_out(_unwritable), ("--out", "Permission denied")),
    "out under /proc": Case(lambda t, mp: ["run", E, "--out", "/proc/mobigrasp-run"] + QUICK,
                            ("--out", "/proc/mobigrasp-run")),
    "out not empty, not a run folder": Case(_out(_not_empty), ("--out", "not empty")),
    # run --check refuses the same --out the run would, with the same line
    "check: out a file": Case(_out(_a_file, check=True), ("--out", "is a file")),
    "check: out under a file": Case(_out(_under_a_file, check=True), ("--out",)),
    "check: out a symlink": Case(_out(_a_symlink, check=True), ("--out", "symbolic link")),
    "check: out unwritable": Case(_out(_unwritable, check=True),
                                  ("--out", "Permission denied")),
    "check: out not empty, not a run folder": Case(_out(_not_empty, check=True),
                                                   ("--out", "not empty")),
    "check: out holds a run file not ours": Case(_out(_foreign_trace, check=True),
                                                 ("--out", "trace.jsonl", "did not write")),
    "--time-limit-s inf": Case(lambda t, mp: ["run", E, "--time-limit-s", "inf", "--check"],
                               ("--time-limit-s", "inf")),
    "--time-limit-s nan": Case(lambda t, mp: ["run", E, "--time-limit-s", "nan", "--check"],
                               ("--time-limit-s", "nan")),
    "--time-limit-s 1e12": Case(lambda t, mp: ["run", E, "--time-limit-s", "1e12", "--check"],
                                ("--time-limit-s", "3600")),
    "--seed 2**64": Case(lambda t, mp: ["run", E, "--seed", str(2**64), "--check"], ("--seed",)),
    "f_px 1e-300": Case(_sc(E, ("camera", "f_px"), 1e-300), ("camera.f_px",)),
    "u0_px 1e300": Case(_sc(E, ("camera", "u0_px"), 1e300), ("camera.u0_px",)),
    "noise_std 1e300": Case(_sc(E, ("camera", "noise_std"), 1e300), ("camera.noise_std",)),
    "T_s 0.0": Case(_sc(E, ("params", "T_s"), 0.0), ("params.T_s",)),
    "x_m 1e308": Case(_sc(E, ("robot", "x_m"), 1e308), ("robot.x_m",)),
    "heading_rad 1e308": Case(_sc(E, ("robot", "heading_rad"), 1e308), ("robot.heading_rad",)),
    "time_limit_s 1e12": Case(_sc(E, ("scenario", "time_limit_s"), 1e12),
                              ("scenario.time_limit_s", "3600")),
    "time_limit_s nan": Case(_sc(E, ("scenario", "time_limit_s"), math.nan),
                             ("scenario.time_limit_s",)),
    "seed 2**64": Case(_sc(E, ("scenario", "seed"), 2**64), ("scenario.seed",)),
    "seed 2**70": Case(_sc(E, ("scenario", "seed"), 2**70), ("scenario.seed",)),
    "k_s 0": Case(_sc(E, ("params", "k_s"), 0), ("params.k_s",)),
    "w_min > w_max": Case(_sc(E, ("params", "w_min"), 60), ("params.w_min", "w_max")),
    "theta2_min > theta2_max": Case(_sc(E, ("params", "theta2_max"), -2.9),
                                    ("params.theta2_min", "theta2_max")),
    "obstacle on the robot": Case(_sc(B, ("obstacles", 0), {
        "shape": "circle", "x_m": 0.3, "y_m": 0.0, "radius_m": 0.2}), ("obstacles[0]", "robot")),
    "wall through the robot": Case(_sc(E, ("obstacles",), [
        {"shape": "wall", "x_m": -1.0, "y_m": 0.1, "x2_m": 1.0, "y2_m": 0.1}]), ("obstacles[0]",)),
    "target inside an obstacle": Case(_sc(B, ("obstacles", 1), {
        "shape": "box", "x_m": 5.0, "y_m": 0.5, "width_m": 0.5, "depth_m": 0.3,
        "heading_rad": 0.0}), ("target", "obstacles[1]")),
    "target on the robot": Case(_sc(E, ("target",), {
        "kind": "radial-symbol", "x_m": 0.1, "y_m": 0.0, "heading_rad": 0.0}), ("target", "robot")),
    "path through an obstacle": Case(_sc(M, ("obstacles",), [
        {"shape": "circle", "x_m": 2.1, "y_m": 0.6, "radius_m": 0.2}]), ("target.path[1]",)),
    "path too fast": Case(_sc(M, ("target", "path", 1, "x_m"), 40.0), ("target.path[1]", "m/s")),
    "huge integer for a float": Case(_sc(E, ("robot", "y_m"), 10**400), ("robot.y_m",)),
    "bool for a number": Case(_sc(E, ("camera", "f_px"), True), ("camera.f_px",)),
    "host --port /dev/pts/99": Case(lambda t, mp: ["host", "--port", "/dev/pts/99"],
                                    ("--port", "/dev/pts/99")),
    "host --port a file": Case(lambda t, mp: ["host", "--port", str(_a_file(t, mp))], ("--port",)),
    "host --config not utf8": Case(lambda t, mp: ["host", "--port", "/dev/pts/99", "--config",
                                                  str(_raw(b"\xff")(t, mp)[1])], ("--config",)),
    "console --port /dev/pts/99": Case(lambda t, mp: ["console", "--port", "/dev/pts/99"],
                                       ("/dev/pts/99",)),
    "demo --out a file": Case(lambda t, mp: ["demo", "--out", str(_a_file(t, mp))], ("--out",)),
    "bench --json under /proc": Case(lambda t, mp: ["bench", "protocol", "--frames", "10",
                                                    "--json", "/proc/mobigrasp.json"],
                                     ("/proc/mobigrasp.json",)),
    "campaign --time-limit-s inf": Case(lambda t, mp: ["campaign", "--method", "000", "--runs",
                                                       "1", "--time-limit-s", "inf"],
                                        ("--time-limit-s",)),
    # nesting, huge integers, escaping
    "[faults] nested 5000 deep": Case(
        _raw_scenario(E, "[faults]\nuart_drop_rate = " + "[" * 5000 + "]" * 5000), ("nested",)),
    "[params] nested 40 deep": Case(
        _raw_scenario(E, "", params="v0_mps = " + "[" * 40 + "]" * 40), ("params.v0_mps",)),
    "[faults] 400-digit integer": Case(
        _raw_scenario(E, "[faults]\nuart_drop_rate = " + "9" * 400),
        ("faults.uart_drop_rate", "bits")),
    "--fault 400-digit integer": Case(
        lambda t, mp: ["run", E, "--check", "--fault", "uart_drop_rate=" + "9" * 400],
        ("--fault", "faults.uart_drop_rate")),
    "--fault nested 3000 deep": Case(
        lambda t, mp: ["run", E, "--check", "--fault", "uart_drop_rate=" + "[" * 3000 + "]" * 3000],
        ("--fault", "faults.uart_drop_rate")),
    "--fault escape codes": Case(
        lambda t, mp: ["run", E, "--check", "--fault", "motor_fail.wheel=" + "x\x1b[31m" * 500],
        ("--fault", "motor_fail.wheel", "\\x1b")),
    "--fault unknown key with escape codes": Case(
        lambda t, mp: ["run", E, "--check", "--fault", "\x1b[2J" * 100 + "=1"],
        ("--fault", "unknown key")),
    "scenario a FIFO": Case(lambda t, mp: ["run", str(_fifo(t)), "--check"], ("FIFO",)),
    "scenario a device": Case(lambda t, mp: ["run", "/dev/zero", "--check"], ("/dev/zero",)),
    # host --config: checked before the port is opened
    "host --config nested 5000 deep": Case(_host_config('{"params": ' + "[" * 5000 + "]" * 5000
                                                        + "}"), ("--config", "nested")),
    "host --config u0_px 1e300": Case(_host_config({"camera": {"u0_px": 1e300}}),
                                      ("--config", "camera.u0_px")),
    "host --config w_min > w_max": Case(_host_config({"params": {"w_min": 60, "w_max": 40}}),
                                        ("--config", "params.w_min", "w_max")),
    "host --config params a string": Case(_host_config({"params": "x"}), ("--config", "params")),
    "host --config camera a list": Case(_host_config({"camera": [1]}), ("--config", "camera")),
    "host --config f_px a string": Case(_host_config({"camera": {"f_px": "611"}}),
                                        ("--config", "camera.f_px")),
    "host --config timeout a string": Case(
        _host_config({"task": {"timeouts_us": {"SEARCH": "x"}}}), ("task.timeouts_us.SEARCH",)),
    "host --config timeout 1e300": Case(
        _host_config({"task": {"timeouts_us": {"SEARCH": 10**300}}}), ("task.timeouts_us.SEARCH",)),
    "host --config object_xy_mm 3 values": Case(
        _host_config({"method": "001", "task": {"object_xy_mm": [1, 2, 3]}}),
        ("task.object_xy_mm",)),
    "host --config NaN": Case(_host_config('{"params": {"k1": NaN}}'), ("--config", "NaN")),
    "host --config method 7": Case(_host_config({"method": 7}), ("--config", "method")),
    "host --config a FIFO": Case(lambda t, mp: ["host", "--port", "/dev/pts/99", "--config",
                                                str(_fifo(t))], ("--config", "FIFO")),
    # numbers on command lines: finite, in range (none waits forever)
    "mcu --duration nan": Case(lambda t, mp: ["mcu", "--duration", "nan"], ("--duration",)),
    "mcu --duration -1": Case(lambda t, mp: ["mcu", "--duration", "-1"], ("--duration",)),
    "console --reply-timeout 1e300": Case(lambda t, mp: ["console", "--port", "/dev/pts/99",
                                                         "--reply-timeout", "1e300"],
                                          ("--reply-timeout",)),
    "campaign --jobs 10**30": Case(lambda t, mp: ["campaign", "--method", "000", "--jobs",
                                                  str(10**30)], ("--jobs",)),
    "campaign --runs 0": Case(lambda t, mp: ["campaign", "--method", "000", "--runs", "0"],
                              ("--runs",)),
    "link-demo --count 10**30": Case(lambda t, mp: ["link-demo", "--count", str(10**30)],
                                     ("--count",)),
    "demo --count -1": Case(lambda t, mp: ["demo", "--count", "-1"], ("--count",)),
    "bench protocol --chunk 0": Case(lambda t, mp: ["bench", "protocol", "--chunk", "0"],
                                     ("--chunk",)),
    "bench world --sim-s nan": Case(lambda t, mp: ["bench", "world", "--sim-s", "nan"],
                                    ("--sim-s",)),
    "bench mcu --seconds -5": Case(lambda t, mp: ["bench", "mcu", "--seconds", "-5"],
                                   ("--seconds",)),
    "calibrate --scenario not in the corpus": Case(
        lambda t, mp: ["calibrate", "--corpus", str(_corpus_of("paper000-exp1")(t, mp)),
                       "--scenario", "paper000-exp1", "--scenario", "no-such-scene"],
        ("corpus", "no-such-scene")),
    "calibrate --frames-per-scenario 0": Case(
        lambda t, mp: ["calibrate", "--frames-per-scenario", "0"], ("--frames-per-scenario",)),
}


def _file_named(argv: list[str]) -> str | None:
    """The scenario file a run row is about (its line must name it)."""
    if argv[0] == "run" and argv[1].endswith(".toml"):
        return argv[1]
    return None


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_bad_input_is_exit_2_with_one_line(case, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    row = CASES[case]
    argv = row.argv(tmp_path, monkeypatch)
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's refusal of an option
        code = exc.code
    assert code == 2
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert len(lines) == 1, out.err
    # the value is escaped and cut: no control characters, no screenful
    assert lines[0].isprintable() and len(lines[0]) < 400, lines[0]
    assert "Traceback" not in out.err and "Traceback" not in out.out
    names = row.names + ((_file_named(argv),) if _file_named(argv) else ())
    for name in names:
        assert name in lines[0], (name, lines[0])
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").iterdir())


def test_every_shipped_scenario_passes_the_check(capsys):
    for path in SCENARIOS.values():
        assert main(["run", str(path), "--check"]) == 0, capsys.readouterr().err
        assert capsys.readouterr().out.strip().endswith(": ok")


# --- hypothesis: any value at any key ---------------------------------------------------------

def _paths(node: Any, prefix: tuple = ()) -> list[tuple]:
    """Every key path of a document (tables, arrays of tables, and their leaves)."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append(prefix + (k,))
            out.extend(_paths(v, prefix + (k,)))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append(prefix + (i,))
            out.extend(_paths(v, prefix + (i,)))
    return out


KEY_PATHS = [(name, p) for name in sorted(SCENARIOS) for p in _paths(shipped(name))]
_ANY = object()  # delete the key

hostile = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-300, -1e-300, 1e300, -1e300, 1e308, 5e-324, 3600.0, 3600.5,
                     math.pi, -math.pi, 2 * math.pi + 1e-9]),
    st.integers(min_value=-(2**80), max_value=2**80),
    st.sampled_from([0, 1, -1, 2**63, 2**64, 2**64 - 1]),
    st.text(max_size=20), st.booleans(), st.just([]), st.just({}),
    st.lists(st.integers(-3, 3), max_size=3), st.just(_ANY),
)


def _apply(name: str, path: tuple, value: Any) -> dict:
    doc = shipped(name)
    node = doc
    for k in path[:-1]:
        node = node[k]
    if value is _ANY:
        del node[path[-1]]
    elif isinstance(node, list):
        node[path[-1]] = value
    else:
        node[path[-1]] = value
    return doc


def _answer(doc: dict, tmp: Path, extra: list[str], capsys) -> int:
    p = tmp / "h.toml"
    p.write_text(toml_dumps(doc))
    code = main(["run", str(p)] + extra)
    out = capsys.readouterr()
    assert code in (0, 1, 2)
    assert "Traceback" not in out.err and "Traceback" not in out.out
    if code == 2:
        lines = out.err.strip().splitlines()
        assert len(lines) == 1 and str(p) in lines[0], out.err
    return code


@examples(300,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(key=st.sampled_from(KEY_PATHS), value=hostile)
def test_any_value_at_any_key_is_checked(key, value, tmp_path, capsys):
    _answer(_apply(*key, value), tmp_path, ["--check"], capsys)


@pytest.mark.slow
@examples(60,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(key=st.sampled_from(KEY_PATHS), value=hostile)
def test_any_value_at_any_key_runs_or_is_refused(key, value, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _answer(_apply(*key, value), tmp_path, ["--transport", "inproc", "--time-limit-s", "5",
                                             "--quiet", "--no-plots", "--out",
                                             str(tmp_path / "run")], capsys)


# --- every range end is safe to run ----------------------------------------------------------

def _extremes() -> list[tuple[str, tuple, Any]]:
    """(scenario, key path, value): every camera value and paper parameter that its method
    reads at both ends of its range, on the shipped scenario of its method (an ordered pair's
    partner follows it); the keys a method does not read are refused at load by name
    (tests/unit/mcu_sim/test_scenario_load.py)."""
    from mobigrasp.host.task import REGISTRY
    from mobigrasp.mcu_sim.world.scenario import CAMERA_RANGES

    by_method = {"000": E, "001": B, "002": M}
    out = []
    for method, name in by_method.items():
        for key, (lo, hi) in CAMERA_RANGES.items():
            out += [(name, ("camera", key), lo), (name, ("camera", key), hi)]
        for key, p in REGISTRY[method].paper_params.items():
            if key in REGISTRY[method].not_used_params:
                continue
            for v in (p.lo, p.hi):
                out.append((name, ("params", key), int(v) if p.kind is int else float(v)))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name, path, value", _extremes())
def test_a_value_at_either_end_of_its_range_runs_without_a_crash(name, path, value, tmp_path):
    from mobigrasp.host.task import REGISTRY
    from mobigrasp.services.run_job import RunOptions, execute

    doc = shipped(name)
    doc.setdefault(path[0], {})[path[1]] = value
    method = doc["scenario"]["method"]
    table = REGISTRY[method].paper_params
    # keep an ordered pair ordered (the partner moves)
    for lo, hi, gap in REGISTRY[method].param_order:
        params = {k: p.default for k, p in table.items()} | doc.get("params", {})
        if params[hi] - params[lo] < gap:
            if path[1] == lo:
                doc["params"][lo] = min(value, table[hi].hi - gap)
                doc["params"][hi] = doc["params"][lo] + gap
            else:
                doc["params"][hi] = max(value, table[lo].lo + gap)
                doc["params"][lo] = doc["params"][hi] - gap
    p = tmp_path / "x.toml"
    p.write_text(toml_dumps(doc))
    summary, code = execute(RunOptions(scenario=str(p), transport="inproc", out=tmp_path / "run",
                                       progress=False, plots=False, time_limit_s=8.0))
    assert code in (0, 1) and summary["status"] == "finished", summary.get("error")
