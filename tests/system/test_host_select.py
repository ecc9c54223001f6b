"""``--host python|c|arm``: the C program over the pty and in process (cffi) and the ARMv4T ELF
under qemu-arm -cpu ti925t give the Python host's trace_sha256. Fast: the host program around no
task (the idle method, in every host's table) in paper000-exp1's world; slow: the six shipped
scenarios with their own methods. A method missing from the C table is refused by name (that
test skips once every method is in it)."""

import shutil
import subprocess
import sys

import pytest

from mobigrasp.services.run_job import BadInput, RunOptions, execute
from mobigrasp.tools.check_trace_baseline import SCENARIOS

ARM_TOOLS = bool(shutil.which("qemu-arm") and shutil.which("arm-none-eabi-gcc"))


def _run(tmp_path, host, transport="pty", scenario="paper000-exp1", host_method=None,
         limit_s=None, mcu="python"):
    summary, _ = execute(RunOptions(scenario=scenario, transport=transport, host=host, mcu=mcu,
                                    host_method=host_method, progress=False, plots=False,
                                    mcap=False, time_limit_s=limit_s,
                                    out=tmp_path / f"{scenario}-{host}-{transport}-{mcu}"))
    assert not summary.get("error"), summary.get("error")
    assert summary["host"] == host
    return summary


def test_idle_host_program_same_trace_in_every_host(tmp_path):
    runs = [("python", "inproc"), ("python", "pty"), ("c", "pty"), ("c", "inproc")]
    if ARM_TOOLS:
        runs.append(("arm", "pty"))
    shas = {}
    for host, transport in runs:
        s = _run(tmp_path, host, transport, host_method="idle", limit_s=6.0)
        assert s["end_reason"] == "time_limit" and s["task_state"] == "INIT"
        assert s["host_method"] == "idle" and s["method"] == "000"
        assert s["protocol"]["tx_frames"] > 50  # HELLO and a heartbeat every 100 ms
        assert s["host_steps"]["frames_idle"] > 50  # frame slots passed, the camera off
        shas[host, transport] = s["trace_sha256"]
    assert len(set(shas.values())) == 1, shas
    assert ARM_TOOLS, "qemu-arm and arm-none-eabi-gcc are needed for --host arm (make arm-tools)"


def test_a_method_the_c_host_has_not_is_refused_by_name(tmp_path):
    from mobigrasp import hostc
    from mobigrasp.host.task import METHODS

    have = hostc.program_methods([str(hostc.executable())])
    assert "idle" in have
    missing = [m for m in METHODS if m not in have]
    if not missing:
        pytest.skip("every method is in the C host")
    scenario = {"000": "paper000-exp1", "001": "paper001-sim1", "002": "paper002-marker"}
    done = subprocess.run([sys.executable, "-m", "mobigrasp", "run", "--host", "c",
                           "--no-plots", "--out", str(tmp_path / "r"), scenario[missing[0]]],
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "is not in the C host yet" in lines[0], done.stderr
    assert not (tmp_path / "r").exists()  # refused before anything was written


def test_arm_host_runs_over_the_pty_only(tmp_path):
    with pytest.raises(BadInput, match="--host arm runs over the pty only"):
        _run(tmp_path, "arm", "inproc", host_method="idle", limit_s=1.0)


def test_arm_host_without_qemu_says_what_to_install(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))  # no qemu-arm on it
    with pytest.raises(BadInput, match="needs qemu-arm: install qemu-user"):
        _run(tmp_path, "arm", host_method="idle", limit_s=1.0)


def test_unknown_host_is_bad_input(tmp_path):
    with pytest.raises(BadInput, match="--host must be one of python, c, arm"):
        _run(tmp_path, "fpga")


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENARIOS)
def test_shipped_scenario_same_trace_in_the_c_and_arm_hosts(tmp_path, name):
    """The scenario's method in the C program over the pty and in process and in the ARM ELF
    under qemu-arm: the Python host's trace_sha256."""
    c_pty = _run(tmp_path, "c", "pty", name, limit_s=200.0)["trace_sha256"]
    python = _run(tmp_path, "python", "inproc", name, limit_s=200.0)["trace_sha256"]
    assert c_pty == python
    assert _run(tmp_path, "c", "inproc", name, limit_s=200.0)["trace_sha256"] == python
    assert _run(tmp_path, "arm", "pty", name, limit_s=200.0)["trace_sha256"] == python


@pytest.mark.slow
@pytest.mark.parametrize("name", ["paper000-exp1", "paper001-sim1", "paper002-marker"])
def test_both_boards_as_binaries_grasp_with_the_python_hosts_trace(tmp_path, name):
    """The ARMv4T ELF under qemu-arm and the AVR ELF under simavr in one loop: the grasp, and
    the trace of the Python host with the same firmware ELF."""
    if not shutil.which("simavr"):
        pytest.fail("simavr is needed (make toolchains)")
    both = _run(tmp_path, "arm", "pty", name, limit_s=200.0, mcu="simavr")
    assert both["success"] and both["end_reason"] == "task_done", both["end_reason"]
    python = _run(tmp_path, "python", "pty", name, limit_s=200.0, mcu="simavr")
    assert both["trace_sha256"] == python["trace_sha256"]
