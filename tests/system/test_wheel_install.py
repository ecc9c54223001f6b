"""The wheel works outside the clone: built from the checkout's tracked files, installed into a
fresh virtual environment in a temporary folder, it runs a shipped scenario on the Python and the
native MCU, lists the shipped scenarios and runs the README's ``emulated_robot`` example.

The environment takes the third-party packages from this one (a ``.pth`` line naming its
site-packages), so nothing is downloaded; mobigrasp itself comes from the wheel only, which the
test checks. ``make test`` runs this module (it is slow: a build and five processes).
"""

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest
from test_sim_serve import readme_example

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow
STEP_S = 300  # a bound per step, far above its time on a loaded machine


def _tracked_copy(dest: Path) -> Path:
    """The checkout's tracked files (what a fresh clone holds) copied to ``dest``."""
    try:
        names = subprocess.run(["git", "-C", str(ROOT), "ls-files", "-z"], capture_output=True,
                               check=True, timeout=60).stdout.decode().split("\0")
    except (OSError, subprocess.SubprocessError):
        names = None
    if not names or names == [""]:
        shutil.copytree(ROOT, dest, ignore=shutil.ignore_patterns(
            ".venv", "build", "runs", "bench-results", "*.egg-info", "__pycache__", ".git"))
        return dest
    for name in filter(None, names):
        src = ROOT / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name, follow_symlinks=False)
    return dest


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict:
    """``{"bin": the venv's bin folder, "env": the environment to run it in, "cwd"}``."""
    base = tmp_path_factory.mktemp("wheel")
    src = _tracked_copy(base / "src")
    dist = base / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps",
                    "--no-build-isolation", "--wheel-dir", str(dist), str(src)],
                   check=True, capture_output=True, timeout=STEP_S)
    (wheel,) = dist.glob("mobigrasp-*.whl")
    venv = base / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True,
                   timeout=STEP_S)
    py = venv / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "--quiet",
                    "--no-deps", "--no-index", str(wheel)], check=True, capture_output=True,
                   timeout=STEP_S)
    site = Path(subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_path("
                                "'purelib'))"], capture_output=True, text=True, check=True,
                               timeout=STEP_S).stdout.strip())
    # the third-party packages of this environment, after the wheel's own
    (site / "zz_outer_site.pth").write_text(sysconfig.get_path("purelib") + "\n")
    cwd = base / "elsewhere"
    cwd.mkdir()
    env = {"PATH": f"{venv / 'bin'}:/usr/bin:/bin", "HOME": str(base),
           "PYTHONNOUSERSITE": "1", "MOBIGRASP_CACHE_DIR": str(base / "cache"),
           "MOBIGRASP_PROGRESS_INTERVAL_S": os.environ.get("MOBIGRASP_PROGRESS_INTERVAL_S", "5")}
    return {"bin": venv / "bin", "env": env, "cwd": cwd, "wheel": wheel}


def _run(installed: dict, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run(list(argv), cwd=installed["cwd"], env=installed["env"],
                          capture_output=True, text=True, timeout=STEP_S)


def test_the_wheel_holds_the_package_data(installed):
    names = set(zipfile.ZipFile(installed["wheel"]).namelist())
    for name in ("mobigrasp/scenarios/paper000-exp1.toml", "mobigrasp/firmware/fw/program.c",
                 "mobigrasp/firmware/protocol/crc16_table.inc", "mobigrasp/firmware/Makefile",
                 "mobigrasp/firmware/simavr/harness.c", "mobigrasp/hostc_sources/bezier.c",
                 "mobigrasp/protocol/golden_vectors.json", "mobigrasp/services/run_job.py"):
        assert name in names, name
    assert not any(n.startswith(("tests/", "mobigrasp/tests/")) for n in names)


def test_mobigrasp_comes_from_the_wheel(installed):
    out = _run(installed, str(installed["bin"] / "python"), "-c",
               "import mobigrasp.services.run_job as r; print(r.__file__); "
               "print(r.SCENARIO_DIR)")
    assert out.returncode == 0, out.stderr
    venv = str(installed["bin"].parent)
    assert all(line.startswith(venv) for line in out.stdout.split()), out.stdout


def test_scenarios_are_listed(installed):
    out = _run(installed, str(installed["bin"] / "mobigrasp"), "scenarios")
    assert out.returncode == 0, out.stderr
    for name in ("paper000-exp1", "paper001-sim2", "paper002-marker"):
        assert name in out.stdout


@pytest.mark.parametrize("mcu", ["python", "native"])
def test_a_shipped_scenario_runs_and_grasps(installed, mcu):
    out = _run(installed, str(installed["bin"] / "mobigrasp"), "run", "paper000-exp1",
               "--mcu", mcu, "--no-plots", "--out", f"run-{mcu}", "-q")
    assert out.returncode == 0, out.stdout + out.stderr
    summary = json.loads((installed["cwd"] / f"run-{mcu}" / "summary.json").read_text())
    assert summary["grasped"] is True and summary["scenario"] == "paper000-exp1"


def test_the_readme_example_runs(installed):
    code = readme_example()
    (installed["cwd"] / "test_readme_example.py").write_text(code)
    out = _run(installed, str(installed["bin"] / "python"), "-m", "pytest", "-q",
               "-p", "no:cacheprovider", "test_readme_example.py")
    assert out.returncode == 0, out.stdout + out.stderr
    assert "1 passed" in out.stdout
