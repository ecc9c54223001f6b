"""``mobigrasp bench world``: wall time per simulated second of the plant, and per camera frame.

``world_realtime_factor`` is simulated seconds per wall second of ``World.step_to`` at the 1 kHz
physics step (base driving a circle among the obstacles of the 001 example, no rendering; target
>= 100). ``world_with_sensors_realtime_factor`` adds what the rig polls: encoders at 1 kHz and the
five sonars at 20 Hz. ``frame_ms_p50`` / ``frame_ms_p95`` time one 320x240 frame from
``mobigrasp.mcu_sim.world.camera`` (target <= 5 ms), when that renderer is present.
"""

from __future__ import annotations

import argparse
import importlib.util
import time

import numpy as np

from mobigrasp.mcu_sim.world.world import World
from mobigrasp.services.run_job import BadInput, resolve_scenario
from mobigrasp.tools.benches import BenchInputError

NAME = "world"
HELP = "plant speed: simulated seconds per wall second at 1 kHz physics, ms per camera frame"
DEFAULT_SCENARIO = "paper001-sim1"  # shipped: 001 with five obstacles


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of the world benchmark."""
    from mobigrasp.mcu_sim import checks

    parser.add_argument("--scenario", default=DEFAULT_SCENARIO,
                        help="scenario file or shipped name (default: paper001-sim1, "
                             "001 with obstacles)")
    parser.add_argument("--sim-s", type=checks.arg_number(0.0, 3600.0, "s", lo_open=True),
                        default=20.0, help="simulated seconds per run")
    parser.add_argument("--frames", type=checks.arg_int(1, 1_000_000),
                        default=200, help="camera frames to render")


def _run_world(scenario, sim_s: float, sensors: bool) -> float:
    world = World(scenario)
    world.set_wheel_duty(120, 160)
    end_us = int(sim_s * 1e6)
    t0 = time.perf_counter()
    if sensors:
        for t_us in range(1000, end_us + 1, 1000):
            world.step_to(t_us)
            world.encoder_ticks()
            if t_us % 50_000 == 0:
                world.sonar_ranges_m()
    else:
        for t_us in range(20_000, end_us + 1, 20_000):
            world.step_to(t_us)
    return sim_s / (time.perf_counter() - t0)


def _frames(scenario, n: int) -> dict:
    if importlib.util.find_spec("mobigrasp.mcu_sim.world.camera") is None:
        return {"frame_ms_p50": None, "frame_note": "mcu_sim/world/camera.py not present"}
    from mobigrasp.mcu_sim.world import camera

    world = World(scenario)
    world.set_wheel_duty(100, 140)
    world.set_servo_pulse_us(4, 900)  # shoulder down: the camera sees ground and obstacles
    times_ms = []
    for i in range(n):
        world.step_to((i + 1) * 66_000)
        pos, r_wc = world.camera_pose_world()
        scene = world.camera_scene()
        t0 = time.perf_counter()
        camera.render(scene, pos, r_wc, t_us=world.t_us)
        times_ms.append((time.perf_counter() - t0) * 1e3)
    return {"frame_ms_p50": float(np.percentile(times_ms, 50)),
            "frame_ms_p95": float(np.percentile(times_ms, 95)), "frames": n}


def run(args: argparse.Namespace) -> dict:
    """Measure and return the figures (keys carry their units)."""
    try:
        scenario = resolve_scenario(args.scenario)[1]
    except BadInput as exc:
        raise BenchInputError(str(exc)) from exc
    _run_world(scenario, 1.0, False)  # warm-up (imports, caches)
    out = {
        "scenario": scenario.meta.name,
        "physics_step_us": 1000,
        "sim_s": args.sim_s,
        "world_realtime_factor": _run_world(scenario, args.sim_s, False),
        "world_with_sensors_realtime_factor": _run_world(scenario, args.sim_s, True),
    }
    out.update(_frames(scenario, args.frames))
    return out
