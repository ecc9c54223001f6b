"""``mobigrasp bench fuzz``: mutated byte streams into the firmware's frame parser and dispatch.

Each input is a few valid host -> MCU frames (every command type, PARAM_SETs of the safety
parameters included, values anywhere in their wire ranges) with one corruption applied inside a
window of them that ends at an intact 0x00 (bit flips, replaced, inserted or deleted bytes, a
lost delimiter, a frame cut short, a burst of noise), followed by two intact frames. The bytes
go through the firmware's own parser and ``handle_frame`` in process (one emulated ATmega128,
session open). Reported, per docs/protocol.md §2.1 and docs/firmware.md "Safety limits":

- ``crashes``: exceptions anywhere in parse or dispatch (must be 0);
- ``frames_lost_after_corruption``: intact frames after the window's 0x00 not delivered (must
  be 0: COBS resynchronises at every 0x00);
- ``frames_lost_after_lost_delimiter``: of the inputs whose corruption is one lost delimiter,
  how often the frame after it was not delivered (the parser's tail search; ~0);
- ``frames_never_sent``: delivered frames that were not in the input (CRC-16 false accepts),
  and of those ``never_sent_actuated`` (changed a servo or wheel target);
- ``limit_violations``: checks after every dispatched frame that the servo bank stays inside
  the mechanical limits, the watchdog in 50..1000 ms and the wheel targets within the
  protocol's 1000 mm/s (must be 0).
"""

from __future__ import annotations

import random
import struct
import time
from operator import le

from mobigrasp.services.fuzz_inputs import MUTATIONS, command, mutate

NAME = "fuzz"
POOL_FRAMES = 4096
HELP = "mutated frames into the firmware's parser and dispatch: crashes, lost and false frames"


def add_arguments(parser) -> None:
    """Bench options."""
    from mobigrasp.mcu_sim import checks

    parser.add_argument("--inputs", type=checks.arg_int(1, 10**12), default=1_000_000,
                        help="mutated inputs (default 1000000); with --c: libFuzzer inputs, "
                             "shared by the three C targets")
    parser.add_argument("--seed", type=checks.arg_int(0, 2**31 - 1), default=1,
                        help="seed of the inputs (default 1)")
    parser.add_argument("--jobs", type=checks.arg_int(1, 256), default=None,
                        help="processes, each with its own emulated MCU and share of the "
                             "inputs (default 1; more pays on idle cores only)")
    parser.add_argument("--c", action="store_true",
                        help="fuzz the C protocol code instead (services/fuzz_c.py: "
                             "libFuzzer with ASan+UBSan, and the C parser against the Python)")
    parser.add_argument("--diff-inputs", type=checks.arg_int(0, 10**10), default=100_000,
                        help="with --c: inputs of the differential run (default 100000)")
    parser.add_argument("--max-seconds", type=checks.arg_int(1, 10**7), default=None,
                        help="with --c: wall seconds each C target may take at most (the "
                             "figures say how many inputs ran); default: no limit")


def _violations(fw, mech) -> int:
    """Limit checks of the firmware state after a dispatched frame; the number that fail.

    First all of them at once over the concatenated tables (two passes instead of ten: this
    runs after every frame), counted one by one only when that finds something."""
    from mobigrasp.mcu_sim.firmware import params as P

    s = fw.servos
    lo_us, hi_us, lo8, hi8 = mech[:4]
    values = s.min_us + s.max_us + s.target_q8 + s.pending_q8 + s.latched_q8
    if all(map(le, mech[4], values)) and all(map(le, values, mech[5])) \
            and all(map(le, s.min_us, s.max_us)) \
            and P.WATCHDOG_MIN_MS <= fw.params.get(P.P_WATCHDOG_MS) <= P.WATCHDOG_MAX_MS \
            and -1000 <= fw.wheels[0].target_mmps <= 1000 \
            and -1000 <= fw.wheels[1].target_mmps <= 1000:
        return 0
    bad = 0
    for values, lo, hi in ((s.min_us, lo_us, hi_us), (s.max_us, lo_us, hi_us),
                           (s.target_q8, lo8, hi8), (s.pending_q8, lo8, hi8),
                           (s.latched_q8, lo8, hi8)):
        if not all(map(le, lo, values)) or not all(map(le, values, hi)):
            bad += 1
    if not all(map(le, s.min_us, s.max_us)):
        bad += 1
    if not P.WATCHDOG_MIN_MS <= fw.params.get(P.P_WATCHDOG_MS) <= P.WATCHDOG_MAX_MS:
        bad += 1
    for wheel in fw.wheels:
        if abs(wheel.target_mmps) > 1000:
            bad += 1
    return bad


def _targets(fw) -> tuple:
    return (tuple(fw.servos.target_q8), fw.wheels[0].target_mmps, fw.wheels[1].target_mmps)


def fuzz(n_inputs: int, seed: int) -> dict:
    """Run ``n_inputs`` mutated inputs; the figures (see the module docstring)."""
    from mobigrasp.mcu_sim.firmware.dispatch import handle_frame
    from mobigrasp.mcu_sim.mcu import Mcu
    from mobigrasp.protocol import messages as m
    from mobigrasp.protocol.frame import encode_raw
    from mobigrasp.protocol.joints import MECH_LIMITS_US

    rng = random.Random(seed)
    mcu = Mcu()
    fw = mcu.firmware
    parser = fw.parser
    mech = (tuple(lo for lo, _ in MECH_LIMITS_US), tuple(hi for _, hi in MECH_LIMITS_US),
            tuple(lo << 8 for lo, _ in MECH_LIMITS_US), tuple(hi << 8 for _, hi in MECH_LIMITS_US))
    # the bounds of min_us + max_us + target_q8 + pending_q8 + latched_q8, concatenated
    mech += (list(mech[0] * 2 + mech[2] * 3), list(mech[1] * 2 + mech[3] * 3))
    now = 1000
    for frame in parser.feed(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "fuzz", 0), 0)):
        handle_frame(fw, frame, now)
    # a pool of encoded commands with random seqs, drawn from for every input (encoding them per
    # input would cost more than the fuzzing); repeats exercise the duplicate filter too
    pool = []
    for _ in range(POOL_FRAMES):
        msg_type, payload = command(rng)
        seq = rng.randrange(256)
        pool.append((encode_raw(m.PROTOCOL_VERSION, seq, msg_type, payload),
                     bytes((m.PROTOCOL_VERSION, seq, msg_type)) + payload))
    out = {"inputs": 0, "input_bytes": 0, "crashes": 0, "frames_sent": 0,
           "frames_delivered": 0, "frames_lost_after_corruption": 0,
           "lost_delimiter_inputs": 0, "frames_lost_after_lost_delimiter": 0,
           "frames_never_sent": 0, "never_sent_actuated": 0, "limit_violations": 0}
    by_kind = dict.fromkeys(MUTATIONS, 0)
    first_crash = ""
    header = struct.Struct("<BBB").pack
    t0 = time.perf_counter()
    for _ in range(n_inputs):
        picked = rng.choices(pool, k=rng.randint(3, 6))
        wires = [w for w, _ in picked]
        keys = [key for _, key in picked]  # version, seq, type, payload of each frame sent
        window = wires[:-2]
        kind, bad, k = mutate(rng, window)
        by_kind[kind] += 1
        stream = bad + wires[-2] + wires[-1]
        out["inputs"] += 1
        out["input_bytes"] += len(stream)
        out["frames_sent"] += len(wires)
        sent = set(keys)
        try:
            frames = parser.feed(stream)
            out["frames_delivered"] += len(frames)
            delivered = set()
            for f in frames:
                key = header(f.version, f.seq, f.msg_type) + f.payload
                delivered.add(key)
                now += 1000
                if key in sent:
                    handle_frame(fw, f, now)
                else:  # a CRC false accept: dispatched like any frame, and watched
                    out["frames_never_sent"] += 1
                    before = _targets(fw)
                    handle_frame(fw, f, now)
                    if _targets(fw) != before:
                        out["never_sent_actuated"] += 1
                out["limit_violations"] += _violations(fw, mech)
            out["frames_lost_after_corruption"] += (keys[-2] not in delivered) + (
                keys[-1] not in delivered)
            if k is not None:  # the frame after a lost delimiter or a cut frame
                out["lost_delimiter_inputs"] += 1
                out["frames_lost_after_lost_delimiter"] += keys[k + 1] not in delivered
        except Exception as exc:  # counted and shown: the bench must report, not stop
            out["crashes"] += 1
            if not first_crash:
                first_crash = f"{type(exc).__name__}: {exc}"
            parser.reset()
    wall = time.perf_counter() - t0
    out["wall_s"] = wall
    out["inputs_per_s"] = out["inputs"] / wall if wall > 0 else 0.0
    out["mutations"] = by_kind
    out["parser"] = parser.stats.as_dict()
    out["first_crash"] = first_crash
    out["seed"] = seed
    return out


def _share(job: tuple[int, int]) -> dict:
    return fuzz(*job)


def merge(parts: list[dict], wall_s: float) -> dict:
    """The figures of workers that ran shares of the inputs, as one run's."""
    out: dict = {}
    for part in parts:
        for key, value in part.items():
            if isinstance(value, int) and not isinstance(value, bool):
                out[key] = out.get(key, 0) + value
            elif isinstance(value, dict):
                into = out.setdefault(key, {})
                for k, v in value.items():
                    into[k] = into.get(k, 0) + v
    out["first_crash"] = next((p["first_crash"] for p in parts if p["first_crash"]), "")
    out["seed"] = parts[0]["seed"]
    out["workers"] = len(parts)
    out["wall_s"] = wall_s
    out["inputs_per_s"] = out["inputs"] / wall_s if wall_s > 0 else 0.0
    return out


def run(args) -> dict:
    """Run the fuzz and return its figures: over ``--jobs`` processes (worker k seeded with
    ``seed + k``, one worker: exactly ``fuzz(inputs, seed)``), or the C fuzz with ``--c``."""
    n = int(getattr(args, "inputs", 1_000_000))
    seed = int(getattr(args, "seed", 1))
    if getattr(args, "c", False):
        from mobigrasp.services.fuzz_c import run_c

        return run_c(n, seed, int(getattr(args, "diff_inputs", 100_000)),
                     getattr(args, "max_seconds", None))
    jobs = min(getattr(args, "jobs", None) or 1, n)
    if jobs == 1:
        return fuzz(n, seed)
    from concurrent.futures import ProcessPoolExecutor

    shares = [(n // jobs + (k < n % jobs), seed + k) for k in range(jobs)]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        parts = list(pool.map(_share, shares))
    return merge(parts, time.perf_counter() - t0)
