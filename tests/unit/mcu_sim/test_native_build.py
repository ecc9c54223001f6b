"""The native module is built on first use into a cache keyed by the sources' hash: a changed
source is a new key (and a new build), an unchanged tree loads what is there."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from mobigrasp.mcu_sim.native import build

ROOT = Path(__file__).resolve().parents[3]


def test_hash_follows_every_source(tmp_path):
    copy = tmp_path / "firmware"
    shutil.copytree(build.FIRMWARE_DIR, copy, ignore=shutil.ignore_patterns("build"))
    base = build.source_hash(copy)
    assert base == build.source_hash(build.FIRMWARE_DIR)
    header = copy / "fw" / "wheel_pi.h"
    header.write_text(header.read_text() + "\n/* a comment */\n")
    changed = build.source_hash(copy)
    assert changed != base
    (copy / "build").mkdir()
    (copy / "build" / "x.c").write_text("int x;\n")  # the avr build folder is not a source
    assert build.source_hash(copy) == changed


def test_first_use_builds_into_an_empty_cache_then_reuses_it(tmp_path):
    env = dict(os.environ, MOBIGRASP_CACHE_DIR=str(tmp_path))
    code = ("from mobigrasp.mcu_sim.native.mcu import NativeMcu; m = NativeMcu(); "
            "m.advance_to(25_000); print(len(m.uart_tx_take()))")
    for _ in range(2):
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, cwd=tmp_path, timeout=300)
        assert res.returncode == 0, res.stderr
        assert res.stdout.strip() == "2"  # telemetry at 0 and 20 ms
    built = list((tmp_path / "native").glob("*/*.so"))
    assert len(built) == 1 and built[0].parent.name == build.source_hash()
    assert not [p for p in (tmp_path / "native").iterdir() if p.name != built[0].parent.name]
