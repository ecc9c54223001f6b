"""``mobigrasp bench fuzz --c``: the C protocol code both boards run, fuzzed.

Three libFuzzer targets (``firmware/fuzz/fuzz_*.c``: the frame parser with message checks on
every frame it delivers, COBS both ways, message decoding), built with clang and
AddressSanitizer + UndefinedBehaviorSanitizer, each run for its share of ``--inputs`` from a
seed corpus of valid frames; and a differential run of the same C parser (built through cffi,
``firmware/fuzz/diff_feed.c``) against the Python reference ``protocol.FrameParser`` and
``protocol.messages``: every delivered frame, every counter and every NACK reason must agree.

Reported per target: inputs run, ``crashes`` (libFuzzer stops at the first: an abort of a
target's own check, a signal, or a sanitizer report), ``sanitizer_reports`` and the input that
caused it; for the differential run ``disagreements`` and the first one. All must be 0.
"""

from __future__ import annotations

import hashlib
import os
import random
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

from mobigrasp import cbuild
from mobigrasp.resources import data_dir

FIRMWARE_DIR = data_dir("mobigrasp.firmware")  # the protocol C and the fuzz harnesses
TARGETS = ("fuzz_frame", "fuzz_cobs", "fuzz_messages")
# a delivered frame is at most 71 wire bytes: a few frames and the runs between them
MAX_LEN = {"fuzz_frame": 512, "fuzz_cobs": 253, "fuzz_messages": 65}
CFLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-g", "-O1",
          "-fsanitize=fuzzer,address,undefined", "-fno-sanitize-recover=undefined")
_SANITIZER = re.compile(r"ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer)"
                        r"|runtime error:")
_PROTOCOL_SOURCES = ("protocol/frame.c", "protocol/cobs.c", "protocol/crc16.c",
                     "protocol/messages.c", "protocol/joints.c")


class FuzzBuildError(RuntimeError):
    """clang or libFuzzer is missing, or a harness does not compile."""


def _hash(extra: str) -> str:
    h = hashlib.sha256(extra.encode())
    for p in sorted([*FIRMWARE_DIR.glob("protocol/*"), *FIRMWARE_DIR.glob("fuzz/*")]):
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


def build_targets(cc: str = "clang") -> dict[str, Path]:
    """The libFuzzer binaries, built into the cache (``$MOBIGRASP_CACHE_DIR/fuzz/<hash>``)."""
    if shutil.which(cc) is None:
        raise FuzzBuildError(f"{cc}: not found (the C fuzz targets need clang with libFuzzer)")
    target = cbuild.cache_root() / "fuzz" / _hash(" ".join(CFLAGS))
    cbuild.build_once(target, lambda: all((target / t).is_file() for t in TARGETS),
                      lambda: _compile_targets(target, cc))
    return {t: target / t for t in TARGETS}


def _compile_targets(target: Path, cc: str) -> None:
    tmp = Path(tempfile.mkdtemp(prefix=f"{target.name}.", dir=target.parent))
    try:
        for t in TARGETS:
            cmd = [cc, *CFLAGS, f"-I{FIRMWARE_DIR}", str(FIRMWARE_DIR / "fuzz" / f"{t}.c"),
                   *(str(FIRMWARE_DIR / s) for s in _PROTOCOL_SOURCES), "-o", str(tmp / t)]
            done = subprocess.run(cmd, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                first = (done.stderr.strip().splitlines() or ["(no message)"])[0]
                raise FuzzBuildError(f"building {t} failed: {first}")
        cbuild.rename_into_place(tmp, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def seed_corpus(folder: Path) -> None:
    """Valid frames of every message type (and a few streams of them) as libFuzzer's start."""
    from mobigrasp.protocol import messages as m

    samples = [m.Hello(m.PROTOCOL_VERSION, "fuzz", 3), m.Heartbeat(7),
               m.SetServos(0, (1500,) * 6, 100), m.SetServos(1, (0,) * 6, 0), m.Gripper(500),
               m.SetWheels(-200, 300), m.Stop(), m.ParamGet(1), m.ParamSet(1, 250),
               m.Ack(4), m.Nack(4, 3), m.Log(9, "hello"),
               m.Telemetry(7, 1, 2, (1500,) * 6, (0xFFFF,) * 5, 4, 0, 0, 0, 0)]
    folder.mkdir(parents=True, exist_ok=True)
    wires = [m.encode_message(msg, k) for k, msg in enumerate(samples)]
    for k, wire in enumerate(wires):
        (folder / f"frame{k:02d}").write_bytes(wire)
        (folder / f"payload{k:02d}").write_bytes(bytes((samples[k].MSG_TYPE,))
                                                 + samples[k].encode())
    (folder / "stream").write_bytes(b"".join(wires))


def run_target(binary: Path, inputs: int, seed: int, max_len: int,
               max_seconds: int | None = None) -> dict:
    """Run one libFuzzer target for ``inputs`` inputs (or until ``max_seconds`` of wall time,
    whichever comes first: the figures say how many ran); its figures."""
    with tempfile.TemporaryDirectory(prefix="mobigrasp-fuzz-") as tmp:
        corpus = Path(tmp) / "corpus"
        seed_corpus(corpus)
        env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0",
                   UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
        t0 = time.perf_counter()
        budget = [f"-max_total_time={max_seconds}"] if max_seconds else []
        done = subprocess.run([str(binary), f"-runs={inputs}", f"-seed={seed}",
                               f"-max_len={max_len}", "-print_final_stats=1", *budget,
                               f"-artifact_prefix={tmp}/", str(corpus)],
                              capture_output=True, text=True, env=env, check=False)
        wall = time.perf_counter() - t0
        artifacts = sorted(p.name for p in Path(tmp).glob("crash-*")) + sorted(
            p.name for p in Path(tmp).glob("leak-*")) + sorted(
            p.name for p in Path(tmp).glob("timeout-*"))
        reproducer = (Path(tmp) / artifacts[0]).read_bytes().hex() if artifacts else ""
    log = done.stderr
    ran = re.search(r"stat::number_of_executed_units:\s*(\d+)", log)
    reports = [line for line in log.splitlines() if _SANITIZER.search(line)]
    crashed = done.returncode != 0 or bool(artifacts)
    return {"inputs": int(ran.group(1)) if ran else 0, "crashes": int(crashed),
            "sanitizer_reports": len(reports), "first_report": reports[0][:300] if reports
            else ("" if not crashed else log.strip().splitlines()[-1][:300]),
            "reproducer_hex": reproducer[:2000], "wall_s": round(wall, 2),
            "inputs_per_s": round(int(ran.group(1)) / wall) if ran and wall > 0 else 0}


# --- the differential run: the C parser (cffi) against protocol.FrameParser ------------------

def _diff_module():
    """The C parser and diff_feed as a cffi module (cached like the native firmware)."""
    target = cbuild.cache_root() / "fuzzdiff" / _hash("cffi")

    def configure(ffi) -> None:
        ffi.cdef(cbuild.header_cdef(("fuzz/diff_feed.h",), [FIRMWARE_DIR]))
        ffi.set_source("mobigrasp_fuzzdiff", '#include "fuzz/diff_feed.h"\n',
                       sources=[str(FIRMWARE_DIR / s) for s in
                                (*_PROTOCOL_SOURCES, "fuzz/diff_feed.c")],
                       include_dirs=[str(FIRMWARE_DIR)], extra_compile_args=["-std=c99"])

    return cbuild.load_cached("mobigrasp_fuzzdiff", target,
                              lambda: cbuild.compile_module("mobigrasp_fuzzdiff", target,
                                                            configure, FuzzBuildError),
                              FuzzBuildError)


STAT_FIELDS = ("frames_ok", "crc_errors", "oversize", "unknown_type", "bad_version",
               "truncated", "cobs_errors", "garbage_bytes", "bytes_in", "recovered")
_OUT_CAP = 1 << 16


def _py_reason(frame) -> int:
    from mobigrasp.protocol.messages import MessageError, decode_frame

    try:
        decode_frame(frame)
    except MessageError as exc:
        return exc.nack_reason
    return 0


def _c_frames(out: bytes) -> list[tuple]:
    frames, i = [], 0
    while i < len(out):
        n = out[i]
        frames.append((out[i + 1], out[i + 2], out[i + 3], bytes(out[i + 5:i + 5 + n]),
                       out[i + 4]))
        i += 5 + n
    return frames


def _inputs(rng: random.Random, pool: list[bytes]):
    """Byte streams: valid frames with one corruption (the Python bench's mutator), or random
    bytes with a zero now and then, or valid frames cut and glued anywhere."""
    from mobigrasp.services.fuzz_inputs import mutate

    while True:
        r = rng.random()
        if r < 0.5:
            window = rng.choices(pool, k=rng.randint(1, 5))
            yield mutate(rng, window)[1] + rng.choice(pool)
        elif r < 0.8:
            n = rng.randint(1, 300)
            yield bytes(0 if rng.random() < 0.03 else rng.randrange(256) for _ in range(n))
        else:
            blob = b"".join(rng.choices(pool, k=rng.randint(1, 4)))
            a, b = sorted(rng.randrange(len(blob) + 1) for _ in range(2))
            yield blob[a:b] + rng.choice(pool)


def differential(n_inputs: int, seed: int) -> dict:
    """``n_inputs`` streams through both parsers, persistent across inputs as on a line."""
    from mobigrasp.protocol import messages as m
    from mobigrasp.protocol.frame import FrameParser, encode_raw
    from mobigrasp.services.fuzz_inputs import command

    mod = _diff_module()
    ffi, lib = mod.ffi, mod.lib
    rng = random.Random(seed)
    pool = []
    for _ in range(512):
        msg_type, payload = command(rng)
        if rng.random() < 0.2:  # MCU -> host types and unknown ones too
            msg_type = rng.choice((m.Telemetry.MSG_TYPE, m.Ack.MSG_TYPE, m.Log.MSG_TYPE,
                                   rng.randrange(256)))
        pool.append(encode_raw(rng.choice((m.PROTOCOL_VERSION,) * 9 + (2,)),
                               rng.randrange(256), msg_type, payload[:64]))
    c_parser = ffi.new("frame_parser_t *")
    lib.frame_parser_reset(c_parser)
    py = FrameParser()
    out = ffi.new("uint8_t[]", _OUT_CAP)
    res = {"inputs": 0, "input_bytes": 0, "frames": 0, "disagreements": 0,
           "first_disagreement": ""}
    t0 = time.perf_counter()
    for data, _ in zip(_inputs(rng, pool), range(n_inputs), strict=False):
        res["inputs"] += 1
        res["input_bytes"] += len(data)
        got = _c_frames(ffi.buffer(out, lib.diff_feed(c_parser, data, len(data), out,
                                                       _OUT_CAP))[:])
        want = [(f.version, f.seq, f.msg_type, f.payload, _py_reason(f)) for f in py.feed(data)]
        res["frames"] += len(want)
        c_stats = {k: getattr(c_parser.stats, k) for k in STAT_FIELDS}
        py_stats = {k: v for k, v in py.stats.as_dict().items() if k in STAT_FIELDS}
        if got != want or c_stats != py_stats:
            res["disagreements"] += 1
            if not res["first_disagreement"]:
                res["first_disagreement"] = (f"input {data.hex()}: C {got} {c_stats}, "
                                             f"Python {want} {py_stats}")[:2000]
            lib.frame_parser_reset(c_parser)
            py = FrameParser()
    wall = time.perf_counter() - t0
    res["wall_s"] = round(wall, 2)
    res["inputs_per_s"] = round(res["inputs"] / wall) if wall > 0 else 0
    return res


def run_c(inputs: int, seed: int, diff_inputs: int, max_seconds: int | None = None) -> dict:
    """Every target for inputs / 3 inputs each (at once, a process each, with the differential
    run in this one; ``max_seconds``: the wall time each target may take at most)."""
    from concurrent.futures import ThreadPoolExecutor

    binaries = build_targets()
    share = -(-inputs // len(TARGETS))
    with ThreadPoolExecutor(max_workers=len(TARGETS)) as pool:
        running = {t: pool.submit(run_target, binaries[t], share, seed, MAX_LEN[t], max_seconds)
                   for t in TARGETS}
        diff = differential(diff_inputs, seed)
        targets = {t: f.result() for t, f in running.items()}
    return {"seed": seed, "targets": targets, "differential": diff,
            "inputs": sum(t["inputs"] for t in targets.values()),
            "crashes": sum(t["crashes"] for t in targets.values()),
            "sanitizer_reports": sum(t["sanitizer_reports"] for t in targets.values()),
            "disagreements": diff["disagreements"]}
