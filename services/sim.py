"""A scenario's robot served to an external host program in wall time: what ``mobigrasp sim``
and the pytest plugin's ``emulated_robot`` run.

:func:`serve_scenario` checks the options, resolves the scenario, runs the session
(cosim/serve/session.py) and writes plots/ and report.html; :func:`serve_in_child` is the same
in a child process (multiprocessing), which sends ``("ready", serial, camera_url)`` on its pipe
once both are served, ends on SIGTERM or SIGINT like the command, and exits 0 when the object
was grasped, 1 when not, 2 for bad input.
"""

from __future__ import annotations

import logging
import os
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from mobigrasp.services.run_job import BadInput

log = logging.getLogger(__name__)


def serve_scenario(scenario: str, *, speed: float = 1.0, mcu: str = "python",
                   camera_port: int = 8080, out: Path | None = None, seed: int | None = None,
                   time_limit_s: float | None = None, plots: bool = True, progress: Any = None,
                   on_ready: Callable[[str, str], None] = lambda serial, camera: None,
                   stop: Callable[[], str | None] | None = None) -> dict:
    """Serve one session and return its summary (written to its run folder with the report
    when ``plots``). BadInput for an unknown scenario, a bad option or a camera port in use."""
    from mobigrasp.cosim.serve.session import BadSimInput, SimOptions, serve
    from mobigrasp.services.run_job import check_seed, check_time_limit, resolve_scenario

    check_seed(seed)
    check_time_limit(time_limit_s)
    resolved = resolve_scenario(scenario)
    try:
        summary = serve(SimOptions(scenario=scenario, speed=speed, mcu=mcu,
                                   camera_port=camera_port, out=out, seed=seed,
                                   time_limit_s=time_limit_s, progress=progress,
                                   resolved=resolved), on_ready, stop=stop)
    except BadSimInput as exc:
        raise BadInput(str(exc)) from exc
    if plots:
        try:
            from mobigrasp.services.report import write_report

            write_report(Path(summary["run_folder"]))
        except Exception as exc:  # a plotting failure must not hide the run's result
            log.error("report: %s: %s", type(exc).__name__, exc)
    return summary


def serve_in_child(conn, options: dict, stderr_path: str) -> None:
    """multiprocessing target: :func:`serve_scenario` with ``options``, stderr into
    ``stderr_path``, SIGTERM/SIGINT as the stop; ``("ready", serial, camera)`` or
    ``("bad", message)`` on ``conn``; the exit code says whether the object was grasped."""
    fd = os.open(stderr_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(fd, 2)
    os.close(fd)
    logging.basicConfig(stream=sys.stderr, level=logging.WARNING, format="%(message)s")
    asked: list[str] = []

    def on_signal(signum, frame) -> None:
        asked.append("interrupted" if signum == signal.SIGINT else "terminated")

    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, on_signal)
    try:
        summary = serve_scenario(**options,
                                 on_ready=lambda serial, camera: conn.send(("ready", serial,
                                                                            camera)),
                                 stop=lambda: asked[0] if asked else None)
    except BadInput as exc:
        print(f"mobigrasp sim: {exc}", file=sys.stderr, flush=True)
        conn.send(("bad", str(exc)))
        sys.exit(2)
    sys.exit(0 if summary["grasped"] else 1)
