"""The firmware's PARAM table: ids, names, defaults, ranges (docs/firmware.md lists the same).

In C this is a ``const`` table in flash plus an ``int32_t`` value array in SRAM (4 bytes per
entry, counted in the SRAM budget). Servo limits default to the joint limits of
docs/conventions.md (see ``servo_table.default_limits_us``). Read-only entries report firmware
facts; setting one is refused with NACK_BAD_PARAM, as is an unknown id.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.firmware.servo_table import (
    PULSE_MAX_US,
    PULSE_MIN_US,
    SERVO_COUNT,
    default_limits_us,
)

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

# (id, name, default, min, max, writable)
PARAM_TABLE: tuple[tuple[int, str, int, int, int, bool], ...] = (
    (P_WATCHDOG_MS, "watchdog_ms", 250, 0, 10_000, True),  # 0 disables the watchdog
    (P_TELEMETRY_HZ, "telemetry_hz", 50, 0, 100, True),  # 0 = telemetry off
    (P_WHEEL_KP, "wheel_kp", 16, 0, 1000, True),  # duty per (tick/10 ms), Q8
    (P_WHEEL_KI, "wheel_ki", 2, 0, 1000, True),  # duty per (tick/10 ms x 10 ms), Q8
    (P_WHEEL_MAX_MMPS, "wheel_max_mmps", 800, 0, 1000, True),
    (P_SONAR_COUNT, "sonar_count", 5, 0, 5, True),
    (P_SONAR_SLOT_MS, "sonar_slot_ms", 30, 20, 100, True),
    *((P_SERVO_MIN_BASE + ch, f"servo{ch}_min_us", default_limits_us(ch)[0],
       PULSE_MIN_US, PULSE_MAX_US, True) for ch in range(SERVO_COUNT)),
    *((P_SERVO_MAX_BASE + ch, f"servo{ch}_max_us", default_limits_us(ch)[1],
       PULSE_MIN_US, PULSE_MAX_US, True) for ch in range(SERVO_COUNT)),
    (P_FIRMWARE_VERSION, "firmware_version", FIRMWARE_VERSION, FIRMWARE_VERSION,
     FIRMWARE_VERSION, False),
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
    """Current values, one int32 per table row."""

    def __init__(self) -> None:
        self.values = [0] * len(PARAM_TABLE)
        self.reset()

    def reset(self) -> None:
        """Defaults from the table (power-on)."""
        for i, row in enumerate(PARAM_TABLE):
            self.values[i] = row[2]

    def get(self, pid: int) -> int | None:
        """Value of ``pid``, None if unknown."""
        i = PARAM_INDEX.get(pid)
        return None if i is None else self.values[i]

    def check(self, pid: int, value: int) -> int:
        """0 if ``value`` may be written to ``pid``; else 5 (bad param) or 1 (out of range),
        the protocol's NACK codes."""
        i = PARAM_INDEX.get(pid)
        if i is None or not PARAM_TABLE[i][5]:
            return 5
        _, _, _, lo, hi, _ = PARAM_TABLE[i]
        if not lo <= value <= hi:
            return 1
        if P_SERVO_MIN_BASE <= pid < P_SERVO_MIN_BASE + SERVO_COUNT:
            if value > self.get(pid - P_SERVO_MIN_BASE + P_SERVO_MAX_BASE):
                return 1
        if P_SERVO_MAX_BASE <= pid < P_SERVO_MAX_BASE + SERVO_COUNT:
            if value < self.get(pid - P_SERVO_MAX_BASE + P_SERVO_MIN_BASE):
                return 1
        return 0

    def set(self, pid: int, value: int) -> None:
        """Store a value already accepted by ``check``."""
        self.values[PARAM_INDEX[pid]] = value
