"""The commit a result names: the checkout the package is imported from, in a clone and in a
git worktree (where .git is a file), never "unknown" there."""

import subprocess
from pathlib import Path

import pytest

from mobigrasp.provenance import source_checkout, source_commit

ROOT = Path(__file__).resolve().parents[3]


def _git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True,
                          timeout=30).stdout.strip()


def test_the_checkout_and_its_commit():
    if not _git("rev-parse", "--show-toplevel"):
        pytest.skip("the tests run outside a git checkout (a source archive)")
    assert source_checkout() == ROOT
    head = _git("rev-parse", "--short=12", "HEAD")
    assert source_commit(digits=12).split("+")[0] == head
