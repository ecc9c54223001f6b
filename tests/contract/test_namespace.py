"""One installed namespace: the rooms are importable only as ``mobigrasp.<room>``.

Run from a directory outside the repository, so that the current directory cannot put the
repository's top-level folders on ``sys.path``.
"""

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ROOMS = ("protocol", "link", "host", "mcu_sim", "tools", "services", "cosim", "drivers", "calib",
         "testing")


def _python(code: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, capture_output=True, text=True,
                          timeout=60, env={"PATH": "/usr/bin:/bin", "PYTHONNOUSERSITE": "1"})


@pytest.mark.parametrize("room", ROOMS)
def test_generic_top_level_name_is_not_installed(room, tmp_path):
    out = _python(f"import {room}", tmp_path)
    assert out.returncode != 0
    assert "ModuleNotFoundError" in out.stderr


def test_namespaced_import_works_outside_the_repository(tmp_path):
    code = ("import mobigrasp.protocol, mobigrasp.host.task, mobigrasp.mcu_sim.firmware, "
            "mobigrasp.link.registry, mobigrasp.tools.cli; print(mobigrasp.protocol.__name__)")
    out = _python(code, tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "mobigrasp.protocol"


def test_user_module_named_protocol_does_not_shadow_the_plugin(tmp_path):
    (tmp_path / "protocol.py").write_text("X = 1\n")
    out = _python("import protocol, mobigrasp.mcu_sim.pytest_plugin; print(protocol.X)", tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "1"


def test_python_dash_m_mobigrasp_is_the_cli(tmp_path):
    out = subprocess.run([sys.executable, "-m", "mobigrasp", "--help"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert "usage: mobigrasp" in out.stdout


def test_package_list_covers_every_package_of_the_tree():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(cfg["packages"])
    on_disk = {"mobigrasp"}
    for room, folder in cfg["package-dir"].items():
        if room == "mobigrasp":
            continue
        for init in (ROOT / folder).rglob("__init__.py"):
            rel = init.parent.relative_to(ROOT / folder).parts
            on_disk.add(".".join((room, *rel)))
    assert listed == on_disk
