"""Fuzz inputs shared by the Python fuzz bench and the C fuzz run: host commands as a host or an
attacker could send them, and the corruptions a line or a hostile peer makes of a window of
frames (the bench and ``services/fuzz_c`` draw the same inputs from the same seed)."""

from __future__ import annotations

import random
import struct

_SERVOS_RAW = struct.Struct("<B6hH")


def command(rng: random.Random) -> tuple[int, bytes]:
    """(msg_type, payload) of one host -> MCU command as the host or an attacker could send it:
    mostly valid messages, some with raw fields anywhere in their wire types."""
    from mobigrasp.mcu_sim.firmware import params as P
    from mobigrasp.protocol import messages as m

    r = rng.random()
    if r < 0.2:
        mode = rng.randint(0, 1)
        lim = (500, 2500) if mode == m.SERVO_MODE_PULSE_US else (-3142, 3142)
        msg = m.SetServos(mode, tuple(rng.randint(*lim) for _ in range(6)), rng.randint(0, 65535))
    elif r < 0.3:  # raw: any mode byte, any int16 target (the firmware NACKs what is out of spec)
        return m.SetServos.MSG_TYPE, _SERVOS_RAW.pack(
            rng.randint(0, 3), *(rng.randint(-32768, 32767) for _ in range(6)),
            rng.randint(0, 65535))
    elif r < 0.45:
        msg = m.SetWheels(rng.randint(-1000, 1000), rng.randint(-1000, 1000))
    elif r < 0.5:
        return m.SetWheels.MSG_TYPE, struct.pack("<hh", rng.randint(-32768, 32767),
                                                 rng.randint(-32768, 32767))
    elif r < 0.6:
        msg = m.Gripper(rng.randint(0, 1000))
    elif r < 0.75:
        pid = rng.choice((P.P_WATCHDOG_MS, P.P_WHEEL_MAX_MMPS,
                          P.P_SERVO_MIN_BASE + rng.randint(0, 5),
                          P.P_SERVO_MAX_BASE + rng.randint(0, 5), rng.randint(0, 0xFFFF)))
        value = rng.choice((0, 1, 49, 50, 500, 1000, 1001, 2500, 10_000, -1,
                            rng.randint(-2**31, 2**31 - 1)))
        msg = m.ParamSet(pid, value)
    elif r < 0.8:
        msg = m.ParamGet(rng.randint(0, 0xFFFF))
    elif r < 0.85:
        msg = m.Stop()
    elif r < 0.9:
        msg = m.Hello(m.PROTOCOL_VERSION, "fuzz", rng.randint(0, 0xFFFF))
    else:
        msg = m.Heartbeat(rng.randint(0, 2**32 - 1))
    return msg.MSG_TYPE, msg.encode()


MUTATIONS = ("flip", "replace", "insert", "delete", "lost_delimiter", "cut", "noise")


def mutate(rng: random.Random, window: list[bytes]) -> tuple[str, bytes, int | None]:
    """(kind, bytes, k) of the corrupted window, its last byte (a 0x00) kept intact; ``k`` is
    the index of the frame whose delimiter was lost or that was cut short (else None)."""
    kind = rng.choice(MUTATIONS)
    body = bytearray(b"".join(window)[:-1])  # all but the final delimiter
    k = None
    if kind in ("lost_delimiter", "cut") and len(window) >= 2:
        k = rng.randrange(len(window) - 1)
        start = sum(len(w) for w in window[:k])
        if kind == "lost_delimiter":
            del body[start + len(window[k]) - 1]
        else:
            keep = rng.randint(1, len(window[k]) - 1)
            del body[start + keep:start + len(window[k])]
    elif kind == "flip":
        for _ in range(rng.randint(1, 3)):
            body[rng.randrange(len(body))] ^= 1 << rng.randrange(8)
    elif kind == "replace":
        body[rng.randrange(len(body))] = rng.randrange(256)
    elif kind == "insert":
        body.insert(rng.randrange(len(body) + 1), rng.randrange(256))
    elif kind == "delete":
        del body[rng.randrange(len(body))]
    else:  # noise (or a window of one frame): a burst of random bytes over part of it
        kind = "noise"
        at = rng.randrange(len(body))
        for i in range(at, min(len(body), at + rng.randint(1, 40))):
            body[i] = rng.randrange(256)
    return kind, bytes(body) + b"\x00", k
