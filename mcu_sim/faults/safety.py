"""The safety monitor of a run under faults: what the actuators did, judged from outside.

The rig calls :meth:`SafetyMonitor.observe` at every MCU <-> plant coupling step with what the
motors and servos were given. It counts **unsafe actuations**:

- ``servo_out_of_limits``: a servo pulse outside the joint table of docs/conventions.md (computed
  here from the table, not from the firmware's code, so a firmware bug shows);
- ``motion_in_watchdog_stop``: steps with a non-zero wheel duty while the firmware's watchdog stop
  is active (after the one PWM period the bridge needs to latch the zero duty: OCR0/OCR2 are
  double-buffered, 1024 µs per period, mcu_sim/avr/timer8.py);
- ``late_stops``: host silences (stall or crash) after which the wheels were not stopped within
  the watchdog period + 50 ms of simulated time;
- ``mcu_limit_hits``: commands the firmware had to clamp (the host sent an out-of-limit value);

and the figures of recovery: watchdog trips, the wheel stop latency after each host silence, and
the recovery time after each fault (host stall end or MCU reset -> the firmware accepts commands
again, i.e. watchdog cleared and handshake done). Collisions come from the world (run summary).
"""

from __future__ import annotations

import math

from mobigrasp.protocol import joints

# The joint table (protocol/joints.py): pulse at 0 rad, joint limits in rad (gripper: fraction).
_PULSE0_US = tuple(j.pulse0_us for j in joints.JOINTS)
_LIMITS = tuple((j.lo / 1000, j.hi / 1000) for j in joints.JOINTS)
_K_US_PER_RAD = 2000.0 / math.pi
STOP_MARGIN_US = 50_000
PWM_LATCH_US = 1_100  # one 8-bit PWM period (1024 µs) plus the coupling step's rounding


def joint_pulse_range_us(ch: int) -> tuple[float, float]:
    """Allowed pulse range of channel ``ch`` by the joint table (1 µs tolerance for rounding)."""
    lo, hi = _LIMITS[ch]
    if ch == 0:
        a, b = _PULSE0_US[0] + 1000 * lo, _PULSE0_US[0] + 1000 * hi
    else:
        a, b = _PULSE0_US[ch] + _K_US_PER_RAD * lo, _PULSE0_US[ch] + _K_US_PER_RAD * hi
    return max(500.0, min(a, b)) - 1.0, min(2500.0, max(a, b)) + 1.0


_RANGES = tuple(joint_pulse_range_us(ch) for ch in range(6))


class SafetyMonitor:
    """Counts unsafe actuations and recovery figures of one run (integer µs of simulated time)."""

    def __init__(self, watchdog_us: int = 250_000) -> None:
        self.watchdog_us = watchdog_us
        self.servo_out_of_limits = 0
        self.motion_in_watchdog_stop = 0
        self.late_stops = 0
        self.mcu_limit_hits = 0
        self.watchdog_trips = 0
        self.stop_latency_us: list[int] = []
        self.recovery_us: list[int] = []
        self.unrecovered = 0
        self._silent_since: int | None = None
        self._stopped = False
        self._tripped = False
        self._tripped_us = 0
        self._fault_us: int | None = None  # a fault waiting for recovery
        self._pulses: tuple | None = None  # the last pulses judged and how many were out
        self._pulses_out = 0

    def fault(self, t_us: int) -> None:
        """A fault that needs recovery happened at ``t_us`` (stall end, MCU reset)."""
        if self._fault_us is not None:
            self.unrecovered += 1
        self._fault_us = t_us

    def observe(self, t_us: int, duty: tuple[int, int], pulses_us, watchdog_tripped: bool,
                handshake: bool, host_silent: bool = False) -> None:
        """One coupling step: wheel duties, servo pulses (None/0 before the first), MCU state."""
        if pulses_us != self._pulses:  # pulses change a few times per second: judge them then
            self._pulses = tuple(pulses_us)
            self._pulses_out = sum(1 for ch, p in enumerate(pulses_us)
                                   if p and not _RANGES[ch][0] <= p <= _RANGES[ch][1])
        self.servo_out_of_limits += self._pulses_out
        if watchdog_tripped and not self._tripped:
            self.watchdog_trips += 1
            self._tripped_us = t_us
        self._tripped = watchdog_tripped
        # whether the wheels move matters only in a watchdog stop or a host silence (not
        # computed at the other coupling steps, nearly all of them)
        moving = (watchdog_tripped or host_silent) and (duty[0] != 0 or duty[1] != 0)
        if watchdog_tripped and moving and t_us - self._tripped_us > PWM_LATCH_US:
            self.motion_in_watchdog_stop += 1
        if host_silent:
            if self._silent_since is None:
                self._silent_since, self._stopped = t_us, False
            if not self._stopped and not moving:
                self._stopped = True
                self.stop_latency_us.append(t_us - self._silent_since)
            if not self._stopped and t_us - self._silent_since > self.watchdog_us + STOP_MARGIN_US:
                self._stopped = True  # counted once per silence
                self.late_stops += 1
        elif self._silent_since is not None:
            self._silent_since = None
        if self._fault_us is not None and handshake and not watchdog_tripped and not host_silent:
            self.recovery_us.append(t_us - self._fault_us)
            self._fault_us = None

    def set_limit_hits(self, n: int) -> None:
        """The firmware's count of clamped commands (read at the end of the run)."""
        self.mcu_limit_hits = n

    @property
    def unsafe_actuations(self) -> int:
        """Everything counted as unsafe (collisions are added by the run summary)."""
        return (self.servo_out_of_limits + self.motion_in_watchdog_stop + self.late_stops
                + self.mcu_limit_hits)

    def summary(self) -> dict:
        """The ``safety`` block of summary.json."""
        return {
            "unsafe_actuations": self.unsafe_actuations,
            "servo_out_of_limits": self.servo_out_of_limits,
            "motion_in_watchdog_stop": self.motion_in_watchdog_stop,
            "late_stops": self.late_stops, "mcu_limit_hits": self.mcu_limit_hits,
            "watchdog_trips": self.watchdog_trips,
            "stop_latency_ms": [v / 1000 for v in self.stop_latency_us],
            "recovery_ms": [v / 1000 for v in self.recovery_us],
            "unrecovered": self.unrecovered + (self._fault_us is not None),
        }
