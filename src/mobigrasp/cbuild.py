"""The C parts built with cffi: their declarations, read from the headers, and their cache.

The three cffi builds (the native firmware, the simavr harness, the host kernels of ``hostc/``)
declare to Python exactly what their headers declare, so the two cannot drift apart:
``header_cdef`` runs the C preprocessor on the headers with an empty C library (cffi knows
``<stdint.h>``'s types; nothing else of libc is declared in them), so macros are expanded and
include guards applied, then drops the bodies of ``static inline`` functions, which cffi does not
parse (they stay C-only helpers).

Each built module lives in ``cache_root()`` (``$MOBIGRASP_CACHE_DIR``, default
``~/.cache/mobigrasp``) in a folder named by the hash of its sources: ``load_cached`` loads it or
builds it first; ``compile_module`` builds in a temporary folder renamed into place, so
concurrent first uses never see half a module, and ``build_once`` builds under a file lock, so
they build it once (the others wait for it: a parallel test run's workers start together).
"""

from __future__ import annotations

import fcntl
import importlib.util
import os
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

# The headers the firmware and the kernels take from libc: empty stand-ins (see above).
_LIBC_STANDINS = ("stdint.h", "stddef.h", "stdbool.h", "string.h")


class CBuildError(RuntimeError):
    """The headers could not be preprocessed into declarations."""


def header_cdef(headers: Iterable[str], include_dirs: Iterable[Path],
                defines: Iterable[str] = (), cc: str | None = None) -> str:
    """The declarations of ``#include``-ing ``headers`` (names as in an #include line, found in
    ``include_dirs``), preprocessed with ``-D`` ``defines``, without function bodies."""
    compiler = cc or os.environ.get("CC") or "cc"
    if shutil.which(compiler) is None:
        raise CBuildError(f"{compiler}: no C compiler to read the headers with")
    unit = "".join(f'#include "{h}"\n' for h in headers)
    with tempfile.TemporaryDirectory(prefix="mobigrasp-cdecl-") as tmp:
        for name in _LIBC_STANDINS:
            (Path(tmp) / name).write_text("")
        args = [compiler, "-E", "-P", "-nostdinc", "-I", tmp,
                *(f"-I{d}" for d in include_dirs), *(f"-D{d}" for d in defines), "-x", "c", "-"]
        done = subprocess.run(args, input=unit, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        first = (done.stderr.strip().splitlines() or ["(no message)"])[0]
        raise CBuildError(f"preprocessing {', '.join(headers)} failed: {first}")
    return drop_function_bodies(done.stdout)


def drop_function_bodies(text: str) -> str:
    """``text`` without function definitions: a top-level ``{`` right after a ``)`` opens a
    body; the definition from the end of the previous declaration to its matching ``}`` goes.
    Struct, union and enum bodies follow a name or a keyword, never a ``)``."""
    kept: list[str] = []
    depth, last, i = 0, 0, 0
    while i < len(text):
        c = text[i]
        if c == "{" and depth == 0 and text[last:i].rstrip().endswith(")"):
            start = max(text.rfind(";", last, i), text.rfind("}", last, i)) + 1
            kept.append(text[last:max(start, last)])
            i = _matching_brace(text, i) + 1
            last = i
            continue
        depth += (c == "{") - (c == "}")
        i += 1
    kept.append(text[last:])
    return "".join(kept)


def _matching_brace(text: str, open_at: int) -> int:
    depth = 0
    for j in range(open_at, len(text)):
        depth += (text[j] == "{") - (text[j] == "}")
        if depth == 0:
            return j
    raise CBuildError("unbalanced braces in a preprocessed header")


def cache_root() -> Path:
    """$MOBIGRASP_CACHE_DIR, default ``~/.cache/mobigrasp``: every built C part is kept below."""
    root = os.environ.get("MOBIGRASP_CACHE_DIR")
    return Path(root) if root else Path.home() / ".cache" / "mobigrasp"


def rename_into_place(tmp: Path, target: Path) -> None:
    """``tmp`` becomes ``target``, unless a concurrent build put a ``target`` there first."""
    try:
        os.rename(tmp, target)
    except OSError:
        if not target.is_dir():  # not a concurrent build that won the race
            raise


def build_once(target: Path, ready: Callable[[], bool], build: Callable[[], object]) -> None:
    """``build()`` unless ``ready()``: under an exclusive lock on ``<target>.lock`` beside
    ``target``, with ``ready()`` asked again once the lock is held, so processes that want the
    same part at once build it once and the others wait for it. The build's own rename into
    place keeps the part whole; the lock only spares the duplicate work, so its file goes
    when the build is over (a process that then locks a new one builds again at worst) and the
    cache holds the built parts only."""
    if ready():
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    lock_path = target.parent / f"{target.name}.lock"
    with open(lock_path, "ab") as lock:
        fcntl.flock(lock.fileno(), fcntl.LOCK_EX)  # released when the file closes
        try:
            if not ready():
                build()
        finally:
            lock_path.unlink(missing_ok=True)


def load_cached(name: str, target: Path, build: Callable[[], Path],
                error: type[Exception] = RuntimeError):
    """The extension module ``name`` from the folder ``target`` of the cache, built there first
    by ``build() -> Path`` (the .so) when the folder has none (:func:`build_once`); ``error``
    when it cannot load."""

    def found() -> list[Path]:
        return sorted(target.glob(f"{name}*.so")) if target.is_dir() else []

    build_once(target, lambda: bool(found()), build)
    built = found()
    spec = importlib.util.spec_from_file_location(name, built[0])
    if spec is None or spec.loader is None:
        raise error(f"{built[0]}: cannot be loaded as a module")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def compile_module(name: str, target: Path, configure: Callable[[object], None],
                   error: type[Exception] = RuntimeError) -> Path:
    """Build the cffi module ``name`` into the folder ``target`` and return its .so:
    ``configure(ffi)`` makes the declarations and the source (``cdef``, ``set_source``); a
    failure to read the headers or to compile raises ``error`` with the compiler's message."""
    try:
        import cffi
    except ImportError as exc:  # pragma: no cover - cffi is a dependency
        raise error("building C parts needs cffi (pip install cffi)") from exc
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        ffi = cffi.FFI()
        try:
            configure(ffi)
            so = Path(ffi.compile(tmpdir=str(tmp), verbose=False))
        except Exception as exc:
            raise error(f"building {name} failed: {exc}") from exc
        keep = tmp / "out"
        keep.mkdir()
        shutil.move(str(so), keep / so.name)
        rename_into_place(keep, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return sorted(target.glob(f"{name}*.so"))[0]


def cffi_library(name: str, target: Path, headers: Iterable[str], sources: Iterable[Path],
                 include_dirs: Iterable[Path], error: type[Exception] = RuntimeError):
    """The cffi module ``name`` declaring ``headers`` (:func:`header_cdef`) and compiled from
    ``sources`` as C99 (no float contraction, so the results are the ARM build's), kept in
    ``target``; its ``(ffi, lib)``."""
    dirs = [str(d) for d in include_dirs]

    def configure(ffi) -> None:
        ffi.cdef(header_cdef(tuple(headers), [Path(d) for d in dirs]))
        ffi.set_source(name, "".join(f'#include "{h}"\n' for h in headers),
                       sources=[str(s) for s in sources], include_dirs=dirs,
                       extra_compile_args=["-std=c99", "-O2", "-ffp-contract=off"])

    mod = load_cached(name, target, lambda: compile_module(name, target, configure, error), error)
    return mod.ffi, mod.lib
