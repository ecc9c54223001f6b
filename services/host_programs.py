"""Which host program a run drives (``--host python|c|arm``): its command line over the pty, its
client in process, and the check that it has the method to run.

- ``python``: ``mobigrasp host`` (host/), or in process its LockstepClient (drivers/lockstep.py).
- ``c``: the C program of hostc/ (``mobigrasp.hostc.executable()``, built on first use into the
  cache) with the same options, served by the rig as the Python one; in process the same
  program without its ``main`` through cffi (``hostc/inproc/``, :class:`CProgramClient`).
- ``arm``: the static ARMv4T ELF of ``make hostc-arm`` under ``qemu-arm -cpu ti925t`` over the
  pty (in process there is no ARM CPU: the transport must be the pty).

The C program's methods are read from the program itself (``--list-methods``): a scenario whose
method it has not is refused before anything starts (:class:`HostUnavailable`, exit 2).
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.hosts import host_argv

HOSTS = ("python", "c", "arm")
QEMU = ("qemu-arm", "-cpu", "ti925t")  # an ARMv4T core: a v5 instruction raises SIGILL
DONE_BYTES = 65536  # MG_LS_DONE_BYTES of hostc/lockstep_driver.h
OUT_BYTES = 4096  # MG_LS_OUT_BYTES


class HostUnavailable(ValueError):
    """The host program cannot run this run (bad --host, a tool missing, a method not in its
    table): one line saying what to do."""


@dataclass(frozen=True)
class HostProgram:
    """One host program, resolved: its name, the command line over the pty (``argv(port,
    config, poll_ms)``, without ``--lockstep``) and, for an in-process run, its client on the
    in-process serial end (``inproc(cfg, timer, recorder)(peer)``: HostApp's hooks, which only
    the Python host takes); None where it has none. ``prefix``:
    the C program's command before its options (empty for the Python host)."""

    name: str
    argv: Callable[[str, Path, float], list[str]]
    inproc: Callable[[dict, Any, Any], Callable[[Any], Any]] | None
    prefix: tuple[str, ...] = ()


def _python_inproc(cfg: dict, timer: Any, recorder: Any = None) -> Callable[[Any], Any]:
    """The Python host program's lockstep client on an in-process serial end."""

    def build(peer: Any) -> Any:
        # imported only for an in-process run: over the pty the host program runs in its own
        # process, and this one does not load it
        from mobigrasp.drivers.lockstep import LockstepClient
        from mobigrasp.host.app_factory import build_host_app

        return LockstepClient(build_host_app(cfg, timer=timer, recorder=recorder), peer)

    return build


def _c_argv(prefix: list[str]) -> Callable[[str, Path, float], list[str]]:
    def argv(port_path: str, config_path: Path, poll_ms: float = 0.0) -> list[str]:
        # --poll-ms is accepted and not needed: the C program waits in the kernel
        return [*prefix, "--port", port_path, "--config", str(config_path)]

    return argv


def _c_inproc(cfg: dict, timer: Any, recorder: Any = None) -> Callable[[Any], Any]:
    return lambda peer: CProgramClient(cfg, peer)


def _arm_prefix() -> list[str]:
    """``qemu-arm -cpu ti925t ELF``, the ELF built first; HostUnavailable naming what to
    install when the tools are missing."""
    from mobigrasp.calib.arm import ToolchainError
    from mobigrasp.calib.armhost import build_elf

    if shutil.which(QEMU[0]) is None:
        raise HostUnavailable("--host arm needs qemu-arm: install qemu-user (make arm-tools)")
    try:
        return [*QEMU, str(build_elf())]
    except ToolchainError as exc:
        raise HostUnavailable(f"--host arm needs arm-none-eabi-gcc (make arm-tools): {exc}"
                              ) from exc
    except OSError as exc:  # not run from a checkout: no Makefile to build the ELF with
        raise HostUnavailable(f"--host arm builds the ELF with the checkout's make hostc-arm: "
                              f"{exc}") from exc


def resolve(host: str, method: str, transport: str) -> HostProgram:
    """The host program ``host`` for a run of ``method`` over ``transport``, built and checked
    (it has the method); HostUnavailable otherwise."""
    if host not in HOSTS:
        raise HostUnavailable(f"--host must be one of {', '.join(HOSTS)}, got {host!r}")
    if host == "python":
        return HostProgram("python", host_argv, _python_inproc)
    if host == "arm" and transport != "pty":
        raise HostUnavailable("--host arm runs over the pty only (qemu-arm is its own process)")
    from mobigrasp import hostc

    try:
        prefix = [str(hostc.executable())] if host == "c" else _arm_prefix()
        methods = hostc.program_methods(prefix)
    except hostc.HostcPortBuildError as exc:
        raise HostUnavailable(f"--host {host}: {exc}") from exc
    if method not in methods:
        raise HostUnavailable(f"method {method} is not in the {host.upper()} host yet "
                              f"(it has: {', '.join(methods)})")
    return HostProgram(host, _c_argv(prefix), _c_inproc if host == "c" else None, tuple(prefix))


class CProgramClient:
    """The C host program in this process (hostc/inproc/inproc.h) on the configuration
    ``cfg`` (what ``--config`` gives the program over the pty): what
    drivers/lockstep.LockstepClient is for the Python one. Each GRANT is handed over encoded
    as the rig writes it (its frames in the blob), with the serial bytes it announces, read
    from the in-process serial end; the program's bytes go back there and its DONE is decoded
    as the socket's would be."""

    def __init__(self, cfg: dict, port: Any, read_timeout_s: float = 60.0) -> None:
        import json

        from mobigrasp import hostc
        from mobigrasp.drivers.lockstep import AnnouncedBytes

        self._ffi, self._lib = hostc.program_lib()
        self._host = self._ffi.new("mg_inproc_t *")
        text = json.dumps(cfg).encode()  # the configuration the pty's program reads (--config)
        why = self._ffi.new("char[]", 512)
        if self._lib.mg_inproc_open(self._host, text, len(text), why, 512) != 0:
            raise HostUnavailable(f"the C host refuses the configuration: "
                                  f"{self._ffi.string(why).decode()}")
        self._done = self._ffi.new("uint8_t[]", DONE_BYTES)
        self._out = self._ffi.new("uint8_t[]", OUT_BYTES)
        self._out_len = self._ffi.new("size_t *")
        self.port = port
        self.uart = AnnouncedBytes(port, read_timeout_s)

    def serve(self, grant: ls.Grant) -> ls.Done:
        """Run the C program through one granted quantum; its DONE."""
        data = self.uart.take(grant.uart_bytes) if grant.uart else b""
        msg = ls.encode(grant)
        n = self._lib.mg_inproc_serve(self._host, msg, len(msg), data, len(data), self._done,
                                      DONE_BYTES, self._out, OUT_BYTES, self._out_len)
        if n == 0:
            raise ls.LockstepError(f"the C host refused the GRANT ending at {grant.until_us} us "
                                   f"(malformed, or its DONE or serial bytes too large)")
        if self._out_len[0]:
            self.port.write(bytes(self._ffi.buffer(self._out, self._out_len[0])))
        done = ls.decode(bytes(self._ffi.buffer(self._done, n)))
        if not isinstance(done, ls.Done):
            raise ls.LockstepError(f"the C host answered {type(done).__name__}, not DONE")
        return done

    def after_done(self) -> None:
        """Nothing left over: the C program's vision runs inside its quantum."""

    def bye(self) -> ls.Bye:
        """The program's final statistics."""
        n = self._lib.mg_inproc_bye(self._host, self._done, DONE_BYTES)
        bye = ls.decode(bytes(self._ffi.buffer(self._done, n)))
        if not isinstance(bye, ls.Bye):
            raise ls.LockstepError(f"the C host answered {type(bye).__name__}, not BYE")
        return bye
