"""``mobigrasp sim`` as a function: check the options, resolve the scenario, serve its robot to
an external host program (mobigrasp.cosim.serve.session), then the host's traffic in the
summary, trace.mcap and the report.

What the ``sim`` command and the pytest plugin's wall-clock ``emulated_robot``
(mobigrasp.testing.served_robot) both run: one wiring of the SIM side (cosim/sim_side.py
``SimSide``, through ``serve``), one summary. :func:`serve_scenario` raises BadInput for bad
input (exit code 2, one line) and returns the summary; the caller owns the signals and the
printing.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mobigrasp.services.run_job import (
    BadInput,
    check_seed,
    check_time_limit,
    fault_plan,
    mcap_camera,
    mcap_info,
    resolve_scenario,
    write_report_logged,
)

if TYPE_CHECKING:
    from mobigrasp.cosim.serve.session import SimOptions

log = logging.getLogger(__name__)


def serve_scenario(opts: SimOptions, on_ready: Callable[[str, str, str | None], None],
                   stop: Callable[[], str | None] | None = None, faults: tuple[str, ...] = (),
                   plots: bool = True, progress: Callable[[float, str], Any] | None = None
                   ) -> dict:
    """Serve the robot of ``opts`` (the session's options as ``mobigrasp sim`` takes them; the
    scenario, fault plan, display and trace.mcap are filled in here) until the host closes the
    port, the time limit or ``stop()`` names a reason; ``on_ready(serial, camera_url,
    serial_tcp_url)`` once all are served. ``faults``: ``--fault KEY=VALUE`` overrides;
    ``plots``: plots/ and report.html at the end; ``progress(total_s, scenario_name)`` makes
    the display the session updates (None: none). Returns the summary (also in the run
    folder, ``run_folder`` naming it). BadInput for bad input."""
    from mobigrasp.cosim.serve.session import BadSimInput, serve
    from mobigrasp.mcu_sim.world.scenario import run_time_limit_s
    from mobigrasp.services.mcap_out import McapLog

    check_seed(opts.seed)
    check_time_limit(opts.time_limit_s)
    resolved = resolve_scenario(opts.scenario)
    scenario = resolved[1]
    plan = fault_plan(scenario, faults)
    seed = scenario.meta.seed if opts.seed is None else opts.seed
    # trace.mcap, written as the session goes once its folder is taken
    frames = McapLog(info=mcap_info(scenario, seed, opts.mcu, "pty", "external"),
                     camera=mcap_camera(scenario))
    display = None if progress is None else progress(
        round(run_time_limit_s(scenario, opts.time_limit_s), 1), scenario.meta.name)
    try:
        summary = serve(replace(opts, progress=display, resolved=resolved, plan=plan,
                                on_frame=frames.on_frame,
                                on_folder=lambda out: frames.start(out / "trace.mcap")),
                        on_ready, stop=stop)
    except BadSimInput as exc:
        raise BadInput(str(exc)) from exc
    folder = Path(summary["run_folder"])
    _write_traffic(folder, summary, frames)
    if plots:
        write_report_logged(folder)
    return summary


def _write_traffic(folder: Path, summary: dict, frames: Any) -> None:
    """The host's traffic from the trace into summary.json, and trace.mcap; a failure is
    reported, never hides the session's result."""
    from mobigrasp.cosim.run_folder import read_trace, write_summary
    from mobigrasp.services.wire_traffic import host_traffic

    try:
        events = read_trace(folder / "trace.jsonl")
        summary["host_traffic"] = host_traffic(events)
        stored = {k: v for k, v in summary.items() if k != "run_folder"}
        write_summary(folder / "summary.json", stored)
        frames.finish(summary)
    except Exception as exc:
        log.error("trace.mcap of %s: %s: %s", folder, type(exc).__name__, exc)


def exit_code(summary: dict) -> int:
    """``mobigrasp sim``'s exit code for a session's summary: 0 grasped, 1 not."""
    return 0 if summary["grasped"] else 1
