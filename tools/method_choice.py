"""The ``--method`` choices: the names of the host's method registry (host/task/method.py); the
``--host`` option of the commands that run the loop.

A lazy container, so that building the parser imports no method: argparse reads it when it
checks a given name or prints the choices, and then the registry is imported (the base install
without the simulation extras can still build every parser).
"""

from __future__ import annotations

from collections.abc import Iterator


class MethodNames:
    """The registered method names, read when asked for (argparse ``choices``)."""

    @staticmethod
    def _names() -> tuple[str, ...]:
        from mobigrasp.host.task.method import METHODS

        return tuple(METHODS)

    def __contains__(self, name: object) -> bool:
        return name in self._names()

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())

    def __len__(self) -> int:
        return len(self._names())


METHOD_CHOICES = MethodNames()


HOST_HELP = ("the host program: python (host/, default), c (hostc/ built with this machine's "
             "compiler; in process through cffi with --transport inproc) or arm (the ARMv4T "
             "ELF under qemu-arm -cpu ti925t, over the pty); docs/porting.md")


def add_host_option(parser) -> None:
    """``--host python|c|arm`` (services/host_programs.py)."""
    parser.add_argument("--host", default="python", choices=("python", "c", "arm"),
                        help=HOST_HELP)
