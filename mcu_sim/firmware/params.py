"""The firmware's PARAM table: ids, names, defaults, ranges (docs/firmware.md lists the same).

In C this is a ``const`` table in flash plus an ``int32_t`` value array in SRAM (4 bytes per
entry, counted in the SRAM budget). Read-only entries report firmware facts; setting one is
refused with NACK_BAD_PARAM, as is an unknown id.

Safety PARAMs (the ``safety`` column: the watchdog, the wheel speed limit and the servo limits)
cannot be talked away over the wire (docs/firmware.md "Safety limits"): their range is the
compile-time bound (the servo limits' range is the channel's mechanical limits of the joint table,
so a PARAM may only narrow them; ``watchdog_ms`` is 50..1000, never off), a value outside it is
NACKed BAD_PARAM, and a HELLO (a new session) puts every one back to its power-on value.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.firmware.servo_table import (
    MECH_MAX_US,
    MECH_MIN_US,
    SERVO_COUNT,
)
from mobigrasp.protocol.messages import NACK_BAD_PARAM, NACK_OUT_OF_RANGE

FIRMWARE_VERSION = 1

P_WATCHDOG_MS = 1
P_TELEMETRY_HZ = 2
P_WHEEL_KP = 3
P_WHEEL_KI = 4
P_WHEEL_MAX_MMPS = 5
P_SONAR_COUNT = 6
P_SONAR_SLOT_MS = 7
P_SERVO_MIN_BASE = 16  # 16..21: servo{ch}_min_us
P_SERVO_MAX_BASE = 24  # 24..29: servo{ch}_max_us
P_FIRMWARE_VERSION = 100

WATCHDOG_MIN_MS = 50
WATCHDOG_MAX_MS = 1000

# (id, name, default, min, max, writable, safety)
PARAM_TABLE: tuple[tuple[int, str, int, int, int, bool, bool], ...] = (
    (P_WATCHDOG_MS, "watchdog_ms", 250, WATCHDOG_MIN_MS, WATCHDOG_MAX_MS, True, True),
    (P_TELEMETRY_HZ, "telemetry_hz", 50, 0, 100, True, False),  # 0 = telemetry off
    (P_WHEEL_KP, "wheel_kp", 16, 0, 1000, True, False),  # duty per (tick/10 ms), Q8
    (P_WHEEL_KI, "wheel_ki", 2, 0, 1000, True, False),  # duty per (tick/10 ms x 10 ms), Q8
    (P_WHEEL_MAX_MMPS, "wheel_max_mmps", 800, 0, 1000, True, True),
    (P_SONAR_COUNT, "sonar_count", 5, 0, 5, True, False),
    (P_SONAR_SLOT_MS, "sonar_slot_ms", 30, 20, 100, True, False),
    *((P_SERVO_MIN_BASE + ch, f"servo{ch}_min_us", MECH_MIN_US[ch],
       MECH_MIN_US[ch], MECH_MAX_US[ch], True, True) for ch in range(SERVO_COUNT)),
    *((P_SERVO_MAX_BASE + ch, f"servo{ch}_max_us", MECH_MAX_US[ch],
       MECH_MIN_US[ch], MECH_MAX_US[ch], True, True) for ch in range(SERVO_COUNT)),
    (P_FIRMWARE_VERSION, "firmware_version", FIRMWARE_VERSION, FIRMWARE_VERSION,
     FIRMWARE_VERSION, False, False),
)
PARAM_INDEX = {row[0]: i for i, row in enumerate(PARAM_TABLE)}
PARAM_BY_NAME = {row[1]: row[0] for row in PARAM_TABLE}


def param_id(name_or_id: str | int) -> int:
    """Resolve a parameter name (or numeric id) to its id; ValueError naming it if unknown."""
    if isinstance(name_or_id, int) and not isinstance(name_or_id, bool):
        if name_or_id in PARAM_INDEX:
            return name_or_id
    elif isinstance(name_or_id, str):
        if name_or_id in PARAM_BY_NAME:
            return PARAM_BY_NAME[name_or_id]
        if name_or_id.isdigit() and int(name_or_id) in PARAM_INDEX:
            return int(name_or_id)
    known = ", ".join(f"{r[0]}={r[1]}" for r in PARAM_TABLE)
    raise ValueError(f"unknown parameter {name_or_id!r}; known: {known}")


class Params:
    """Current values, one int32 per table row, and the power-on values they start from."""

    def __init__(self) -> None:
        self.defaults = [row[2] for row in PARAM_TABLE]  # const in flash in C
        self.values = list(self.defaults)

    def set_default(self, pid: int, value: int) -> None:
        """Build-time choice of a power-on value (already accepted by ``check``)."""
        self.defaults[PARAM_INDEX[pid]] = value

    def reset(self) -> None:
        """Power-on values (start-up)."""
        self.values[:] = self.defaults

    def restore_safety(self) -> bool:
        """A new session (HELLO): every safety PARAM back to its power-on value; True if a
        servo limit changed (the servo bank must take the new limits)."""
        servo_changed = False
        for i, row in enumerate(PARAM_TABLE):
            if row[6] and self.values[i] != self.defaults[i]:
                self.values[i] = self.defaults[i]
                if row[0] >= P_SERVO_MIN_BASE:
                    servo_changed = True
        return servo_changed

    def get(self, pid: int) -> int | None:
        """Value of ``pid``, None if unknown."""
        i = PARAM_INDEX.get(pid)
        return None if i is None else self.values[i]

    def check(self, pid: int, value: int) -> int:
        """0 if ``value`` may be written to ``pid``; else the NACK reason: BAD_PARAM for an
        unknown or read-only id and for a safety PARAM outside its compile-time range,
        OUT_OF_RANGE for another PARAM outside its range or a servo min above its max."""
        i = PARAM_INDEX.get(pid)
        if i is None or not PARAM_TABLE[i][5]:
            return NACK_BAD_PARAM
        _, _, _, lo, hi, _, safety = PARAM_TABLE[i]
        if not lo <= value <= hi:
            return NACK_BAD_PARAM if safety else NACK_OUT_OF_RANGE
        if P_SERVO_MIN_BASE <= pid < P_SERVO_MIN_BASE + SERVO_COUNT:
            if value > self.get(pid - P_SERVO_MIN_BASE + P_SERVO_MAX_BASE):
                return NACK_OUT_OF_RANGE
        if P_SERVO_MAX_BASE <= pid < P_SERVO_MAX_BASE + SERVO_COUNT:
            if value < self.get(pid - P_SERVO_MAX_BASE + P_SERVO_MIN_BASE):
                return NACK_OUT_OF_RANGE
        return 0

    def set(self, pid: int, value: int) -> None:
        """Store a value already accepted by ``check``."""
        self.values[PARAM_INDEX[pid]] = value
