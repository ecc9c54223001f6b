"""``mobigrasp bench mcu``: simulated seconds per wall second of the emulated ATmega128 alone.

Telemetry at 50 Hz, an in-process host streaming SET_WHEELS at 50 Hz (plus a SET_SERVOS with
slew every second), and the wheels-in-the-air plant closing the wheel PI loop every 10 ms. The
wall time covers the MCU, the plant and the host stub; ``realtime_factor`` is the same number as
``sim_s_per_wall_s`` (target >= 50; >= 2 for simavr, the firmware asleep in its idle loop).
``--mcu native`` (or ``simavr``) measures that backend and, in the same invocation, the Python
model on the same script, taking turns run by run (best of ``--rounds`` each, so the machine's
drift lands on both), and reports their ratio.
"""

from __future__ import annotations

import time

NAME = "mcu"
START_US = 20_000
# simulated s per wall s each backend is held to: the models 50, the instruction-accurate core 2
TARGET_REALTIME_FACTOR = {"python": 50, "native": 50, "simavr": 2}
HELP = "emulated MCU speed: simulated s per wall s with 50 Hz telemetry and 50 Hz commands"


def add_arguments(parser) -> None:
    """Bench options."""
    from mobigrasp.mcu_sim import checks

    parser.add_argument("--seconds", type=checks.arg_int(1, 3600),
                        default=20, help="simulated seconds (default 20)")
    parser.add_argument("--telemetry-hz", type=checks.arg_int(0, 100), default=50,
                        help="telemetry rate of the MCU in Hz (default 50)")
    parser.add_argument("--command-hz", type=checks.arg_int(1, 100), default=50,
                        help="rate of host commands in Hz (default 50)")
    parser.add_argument("--mcu", default="python",
                        help="MCU backend (python, native, simavr); another than python is "
                             "measured beside python, with the ratio")
    parser.add_argument("--rounds", type=checks.arg_int(1, 1000), default=3,
                        help="runs per backend, taking turns; the best counts (default 3)")


def run(args) -> dict:
    """Run the scenario and return its figures."""
    from mobigrasp.mcu_sim.backend import MCU_BACKENDS

    backend = str(getattr(args, "mcu", "python"))
    rounds = int(getattr(args, "rounds", 3))
    if backend not in MCU_BACKENDS:
        raise ValueError(f"--mcu must be one of {', '.join(sorted(MCU_BACKENDS))}, "
                         f"got {backend!r}")
    if rounds < 1:
        raise ValueError("need --rounds >= 1")
    names = [backend] if backend == "python" else [backend, "python"]
    best: dict[str, dict] = {}
    for _ in range(rounds):
        for name in names:
            res = _measure(args, name)
            if name not in best or res["wall_s"] < best[name]["wall_s"]:
                best[name] = res
    out = dict(best[backend], mcu=backend)
    if backend != "python":
        py = best["python"]
        out["python_sim_s_per_wall_s"] = py["sim_s_per_wall_s"]
        out[f"{backend}_vs_python"] = round(py["wall_s"] / out["wall_s"], 2)
        # the same script gives the same bytes on both backends
        out["same_bytes_as_python"] = (py["rx_bytes"], py["tx_bytes"], py["frames_from_mcu"]) \
            == (out["rx_bytes"], out["tx_bytes"], out["frames_from_mcu"])
    return out


def _measure(args, backend: str) -> dict:
    from mobigrasp.mcu_sim.backend import open_mcu
    from mobigrasp.mcu_sim.bench_plant import WheelsInTheAir
    from mobigrasp.mcu_sim.mcu import McuConfig
    from mobigrasp.mcu_sim.mcu_host import InProcessHost
    from mobigrasp.protocol.frame import PROTOCOL_VERSION
    from mobigrasp.protocol.messages import Hello, SetServos, SetWheels, encode_message
    from mobigrasp.protocol.reliable import SequenceCounter

    seconds = int(getattr(args, "seconds", 20))
    tel_hz = int(getattr(args, "telemetry_hz", 50))
    cmd_hz = int(getattr(args, "command_hz", 50))
    if seconds <= 0 or not 1 <= cmd_hz <= 100 or not 0 <= tel_hz <= 100:
        raise ValueError("need --seconds > 0, --command-hz 1..100, --telemetry-hz 0..100")
    mcu = open_mcu(backend, McuConfig(params={"telemetry_hz": tel_hz}))
    host = InProcessHost(mcu, decode=False)
    plant = WheelsInTheAir()
    step_us = 10_000
    cmd_period_us = 1_000_000 // cmd_hz
    end_us = seconds * 1_000_000
    # The host's frames are encoded before the clock starts: the figure is the MCU's speed.
    # The host starts talking at START_US: the ELF under simavr spends its first 2.2 ms in
    # start-up before its RX interrupt is on (docs/firmware.md), the models none.
    seq = SequenceCounter()
    script: dict[int, list[bytes]] = {START_US: [
        encode_message(Hello(PROTOCOL_VERSION, "bench", 0), seq.next())]}
    for t_cmd in range(START_US, end_us, cmd_period_us):
        slot = t_cmd - t_cmd % step_us
        phase = (t_cmd // 1_000_000) % 2
        wires = script.setdefault(slot, [])
        wires.append(encode_message(SetWheels(300 if phase else -200, 250), seq.next()))
        if t_cmd % 1_000_000 == 0:
            wires.append(encode_message(
                SetServos(0, (1000 + 500 * phase, 1400, 1600, 1500, 1500, 1700), 800), seq.next()))
    t = 0
    wall0 = time.perf_counter()
    while t < end_us:
        for wire in script.get(t, ()):
            host.send_raw(wire)
        ticks = plant.step(mcu.wheel_duty(), step_us)
        t += step_us
        mcu.set_encoder_ticks(ticks[0], ticks[1], t)
        host.run_us(step_us)
    wall = time.perf_counter() - wall0
    stats = mcu.stats()
    ratio = seconds / wall
    return {
        "sim_s": seconds,
        "wall_s": round(wall, 4),
        "sim_s_per_wall_s": round(ratio, 2),
        "realtime_factor": round(ratio, 2),
        "target_realtime_factor": TARGET_REALTIME_FACTOR.get(backend, 50),
        "meets_target": ratio >= TARGET_REALTIME_FACTOR.get(backend, 50),
        "events": stats["events"],
        "events_per_sim_s": stats["events"] // seconds,
        "frames_from_mcu": host.frames,
        "rx_bytes": stats["rx_bytes"],
        "tx_bytes": stats["tx_bytes"],
        "corrupt_frames": stats["corrupt_frames"],
        "wheel_speed_left_mmps": round(plant.speed_mmps[0], 1),
    }
