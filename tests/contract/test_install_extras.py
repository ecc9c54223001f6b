"""Installs sized to the use: the base install is enough for the protocol and the pytest
plugin; `make lint` looks only at tracked files."""

import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HEAVY = ("numpy", "cv2", "pymunk", "matplotlib", "mcap", "distributed")


def _copy_tree(dst: Path) -> Path:
    """The working tree without the venv, build outputs or git (pip builds in the copy)."""
    shutil.copytree(ROOT, dst, symlinks=True, ignore=shutil.ignore_patterns(
        ".venv", ".git", "build", "*.egg-info", "runs", "bench-results", "__pycache__",
        ".hypothesis", ".pytest_cache"))
    return dst


@pytest.mark.slow
def test_base_install_imports_the_protocol_and_the_plugin(tmp_path):
    src = _copy_tree(tmp_path / "src")
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True, system_site_packages=False)
    python = env_dir / "bin" / "python"
    # the project with its base dependencies only, and pytest (the plugin's host)
    subprocess.run([str(python), "-m", "pip", "install", "--quiet", str(src), "pytest"],
                   check=True, capture_output=True, timeout=600)
    probe = (
        "import sys\n"
        "import mobigrasp.protocol.messages as m, mobigrasp.protocol.frame as f\n"
        "from mobigrasp.mcu_sim.pytest_plugin import EmulatedMcu\n"
        "mcu = EmulatedMcu()\n"
        "mcu.advance_ms(60)\n"
        "assert mcu.telemetry(), 'the emulated MCU sends telemetry'\n"
        f"heavy = sorted(k for k in sys.modules if k.split('.')[0] in {HEAVY!r})\n"
        "assert not heavy, heavy\n"
        "print('ok', f.PROTOCOL_VERSION, type(mcu.telemetry()[-1]).__name__)\n")
    done = subprocess.run([str(python), "-c", probe], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("ok ")
    # the CLI still lists every command and names the extra a command needs
    cli = env_dir / "bin" / "mobigrasp"
    helped = subprocess.run([str(cli), "--help"], capture_output=True, text=True, cwd=tmp_path)
    assert helped.returncode == 0 and "campaign" in helped.stdout, helped.stderr
    ran = subprocess.run([str(cli), "run", "paper000-exp1"], capture_output=True, text=True,
                         cwd=tmp_path)
    assert ran.returncode == 2 and "mobigrasp[sim]" in ran.stderr
    assert len(ran.stderr.strip().splitlines()) == 1  # one line, no traceback
    listed = subprocess.run([str(python), "-m", "pip", "list", "--format=freeze"],
                            capture_output=True, text=True, check=True).stdout.lower()
    for name in ("numpy", "opencv-python-headless", "pymunk", "matplotlib", "mcap", "dask"):
        assert f"\n{name}==" not in "\n" + listed, f"the base install pulled {name}"


def test_extras_cover_the_heavy_dependencies():
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    base = " ".join(project["dependencies"])
    extras = project["optional-dependencies"]
    for name in ("numpy", "opencv", "pymunk", "matplotlib", "mcap", "dask"):
        assert name not in base
    assert any(d.startswith("matplotlib") for d in extras["plots"])
    assert any(d.startswith("dask[distributed]") for d in extras["cluster"])
    assert any(d.startswith("pymunk") for d in extras["sim"])
    assert "[sim,plots,cluster,dev]" in (ROOT / "Makefile").read_text()


def test_lint_target_checks_tracked_files_only(tmp_path):
    ruff = Path(sys.executable).with_name("ruff")
    repo = tmp_path / "clone"
    repo.mkdir()
    shutil.copy(ROOT / "Makefile", repo / "Makefile")
    (repo / "good.py").write_text('"""A module."""\n\nX = 1\n')

    def git(*args):
        subprocess.run(["git", *args], cwd=repo, check=True, capture_output=True)

    git("init", "-q")
    git("add", "good.py", "Makefile")
    (repo / "mine").mkdir()
    (repo / "mine" / "scratch.py").write_text("import os\n")  # unused import: F401

    def lint():
        return subprocess.run(["make", "--no-print-directory", "ruff-tracked", f"RUFF={ruff}"],
                              cwd=repo, capture_output=True, text=True, timeout=120)

    assert lint().returncode == 0  # the user's untracked folder is not the project's
    git("add", "mine/scratch.py")
    failed = lint()
    assert failed.returncode != 0 and "F401" in failed.stdout
