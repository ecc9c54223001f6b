"""``mobigrasp bench protocol``: encode and parse throughput against the 115200 8N1 line rate.

The stream is the traffic mix of the closed loop: mostly TELEMETRY (MCU → host at 50 Hz) with
SET_SERVOS, SET_WHEELS, HEARTBEAT and ACK frames. The line-rate baseline is computed, not
measured: 115200 baud / 10 bits per byte = 11,520 bytes/s.
"""

from __future__ import annotations

import argparse
import random
import time

from mobigrasp.protocol import frame as pf
from mobigrasp.protocol import messages as p

NAME = "protocol"
HELP = "frame encode/parse throughput in MB/s and as a multiple of 115200 baud"
LINE_RATE_BYTES_PER_S = 115_200 // 10


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Bench options."""
    from mobigrasp.mcu_sim import checks

    parser.add_argument("--frames", type=checks.arg_int(1, 10_000_000),
                        default=20_000, help="frames in the test stream")
    parser.add_argument("--chunk", type=checks.arg_int(1, 1 << 20),
                        default=4096, help="bytes per parser feed() call")
    parser.add_argument("--repeat", type=checks.arg_int(1, 1000),
                        default=5, help="timed runs; the best is kept")
    parser.add_argument("--seed", type=checks.arg_int(0, 2**63 - 1), default=1,
                        help="seed of the random messages (default 1)")


def traffic(n: int, seed: int) -> list[p.Message]:
    """A seeded message mix like the closed loop's."""
    rng = random.Random(seed)
    out: list[p.Message] = []
    for i in range(n):
        r = rng.random()
        if r < 0.5:
            out.append(p.Telemetry(
                i * 20_000 & 0xFFFFFFFF, rng.randint(-10**6, 10**6), rng.randint(-10**6, 10**6),
                tuple(rng.randint(500, 2500) for _ in range(6)),
                tuple(rng.choice((p.SONAR_NO_ECHO, rng.randint(20, 2500))) for _ in range(5)),
                rng.getrandbits(6), 0, 0, rng.randint(0, 3), 0,
            ))
        elif r < 0.7:
            out.append(p.SetServos(1, tuple(rng.randint(-1500, 1500) for _ in range(6)), 500))
        elif r < 0.85:
            out.append(p.SetWheels(rng.randint(-300, 300), rng.randint(-300, 300)))
        elif r < 0.95:
            out.append(p.Heartbeat(i * 1000))
        else:
            out.append(p.Ack(i & 0xFF))
    return out


def _best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def run(args: argparse.Namespace) -> dict:
    """Measure and return the figures (units in key names)."""
    msgs = traffic(args.frames, args.seed)
    stream = b"".join(p.encode_message(m, i & 0xFF) for i, m in enumerate(msgs))
    chunks = [stream[i:i + args.chunk] for i in range(0, len(stream), args.chunk)]

    def encode_all() -> None:
        for i, m in enumerate(msgs):
            p.encode_message(m, i & 0xFF)

    def parse_all() -> None:
        parser = pf.FrameParser(known_types=p.MESSAGE_TYPES)
        n = 0
        for c in chunks:
            n += len(parser.feed(c))
        if n != len(msgs):
            raise RuntimeError(f"parser returned {n} of {len(msgs)} frames")

    def parse_decode_all() -> None:
        parser = pf.FrameParser(known_types=p.MESSAGE_TYPES)
        for c in chunks:
            for f in parser.feed(c):
                p.decode_frame(f)

    t_enc = _best(encode_all, args.repeat)
    t_parse = _best(parse_all, args.repeat)
    t_dec = _best(parse_decode_all, args.repeat)
    mb = len(stream) / 1e6
    parse_mb = mb / t_parse
    return {
        "stream_bytes": len(stream),
        "frames": len(msgs),
        "mean_frame_bytes": round(len(stream) / len(msgs), 2),
        "encode_mb_per_s": mb / t_enc,
        "encode_frames_per_s": len(msgs) / t_enc,
        "parse_mb_per_s": parse_mb,
        "parse_frames_per_s": len(msgs) / t_parse,
        "parse_decode_mb_per_s": mb / t_dec,
        "line_rate_bytes_per_s": LINE_RATE_BYTES_PER_S,
        "encode_x_line_rate": mb * 1e6 / t_enc / LINE_RATE_BYTES_PER_S,
        "parse_x_line_rate": parse_mb * 1e6 / LINE_RATE_BYTES_PER_S,
        "parse_decode_x_line_rate": mb * 1e6 / t_dec / LINE_RATE_BYTES_PER_S,
        "parse_target_mb_per_s": 5.0,
        "parse_meets_target": parse_mb >= 5.0,
    }
