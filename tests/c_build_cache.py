"""The C builds that the build tests check, kept in the C parts' cache (src/mobigrasp/cbuild.py)
under the hash of what makes them: every file of the source folders (hostc/ and
firmware/protocol/ by default), the Makefile, the compilers' versions and the command. A build
that fails (-Werror: a warning) raises and leaves nothing, so the files found under a hash are
those of a build that succeeded with exactly these inputs; a rerun, or another worker, reads
them instead of compiling again."""

from __future__ import annotations

import hashlib
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from mobigrasp import cbuild

ROOT = Path(__file__).resolve().parents[1]
SOURCES = (ROOT / "hostc", ROOT / "firmware" / "protocol")
_DONE = ".built"


def _version(compiler: str) -> bytes:
    return subprocess.run([compiler, "--version"], capture_output=True, check=True).stdout


def built(kind: str, compilers: Sequence[str], command: Sequence[str],
          make: Callable[[Path], None], sources: Sequence[Path] = SOURCES) -> Path:
    """The folder ``make(folder)`` filled, from the cache when the inputs are the same."""
    h = hashlib.sha256()
    for top in sources:
        for p in sorted(q for q in Path(top).rglob("*") if q.is_file()):
            h.update(str(p).encode() + b"\0" + p.read_bytes())
    h.update((ROOT / "Makefile").read_bytes())
    for compiler in compilers:
        h.update(_version(compiler))
    h.update("\0".join(command).encode())
    target = cbuild.cache_root() / "test-builds" / kind / h.hexdigest()[:16]

    def build() -> None:
        tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
        try:
            make(tmp)
            (tmp / _DONE).touch()
            cbuild.rename_into_place(tmp, target)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)

    cbuild.build_once(target, (target / _DONE).is_file, build)
    return target
