"""Seeded fault injectors besides the UART: camera, host, MCU, motors, sonars, encoders.

All are pure functions of the plan, the run seed and simulated time (integer µs); none reads the
wall clock or keeps a random state that depends on how often it is called. :class:`RunFaults`
bundles them with the two UART directions: it is the one object the rig holds (hook points in
docs/faults.md).
"""

from __future__ import annotations

import numpy as np

from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.uart import UartFaults, derive_key, uniforms


def _us(t_s: float | None) -> int | None:
    return None if t_s is None else round(t_s * 1e6)


class CameraFaults:
    """Frames lost on the CAMIF (``camera_drop_rate``) and sensor noise (``camera_noise_std``)."""

    def __init__(self, plan: FaultPlan, seed: int) -> None:
        self.drop_rate = plan.camera_drop_rate
        self.noise_std = plan.camera_noise_std
        self.key = derive_key(seed, "camera")
        self.dropped = 0

    def drop(self, t_us: int) -> bool:
        """True if the frame captured at ``t_us`` is lost (decided by (seed, t_us) alone)."""
        if not self.drop_rate:
            return False
        lost = bool(uniforms(self.key, np.array([t_us]))[0] < self.drop_rate)
        self.dropped += lost
        return lost

    def noise(self, rgb: np.ndarray, t_us: int) -> np.ndarray:
        """``rgb`` (uint8) plus Gaussian noise of ``noise_std`` grey levels, seeded by (seed, t)."""
        if not self.noise_std:
            return rgb
        rng = np.random.Generator(np.random.PCG64([self.key, int(t_us)]))
        noisy = rgb.astype(np.float32) + rng.normal(0.0, self.noise_std, rgb.shape)
        return np.clip(np.rint(noisy), 0, 255).astype(np.uint8)


class EncoderSlip:
    """Wheel slip: a fraction ``encoder_slip`` of every tick delta never reaches the encoder.

    Integer (Q16) with the remainder carried, so no tick is lost or invented by rounding and the
    result depends only on the sequence of cumulative counts."""

    def __init__(self, slip: float) -> None:
        self.keep_q16 = round((1.0 - slip) * 65536)
        self._last = [0, 0]
        self._acc_q16 = [0, 0]

    def apply(self, left: int, right: int) -> tuple[int, int]:
        """Cumulative true counts (left, right) -> cumulative counts the MCU sees."""
        if self.keep_q16 == 65536:
            return left, right
        out = []
        for side, total in ((0, left), (1, right)):
            delta = total - self._last[side]
            self._last[side] = total
            self._acc_q16[side] += delta * self.keep_q16
            out.append(self._acc_q16[side] >> 16)
        return out[0], out[1]


class RunFaults:
    """Every injector of one run, built from the plan and the run seed."""

    def __init__(self, plan: FaultPlan, seed: int, baud: int = 115_200) -> None:
        self.plan = plan
        self.seed = seed
        self.to_mcu = UartFaults(plan, seed, "host->mcu", baud)
        self.to_host = UartFaults(plan, seed, "mcu->host", baud)
        self.camera = CameraFaults(plan, seed)
        self.slip = EncoderSlip(plan.encoder_slip)
        self.stall = plan.host_stall
        self.crash_us = _us(plan.host_crash_at_s)
        self.mcu_reset_us = _us(plan.mcu_reset_at_s)
        self.mcu_resets = 0
        mf = plan.motor_fail
        self.motor_fail_us = _us(mf.at_s) if mf else None
        self.motor_fail_side = (0 if mf.wheel == "left" else 1) if mf else None
        sf = plan.sonar_fail
        self.sonar_fail_us = _us(sf.at_s) if sf else None
        self.sonar_fail_index = sf.index if sf else None

    # ---- host --------------------------------------------------------------------------------
    def host_stalled(self, t_us: int) -> bool:
        """True while the host program is frozen (``host_stall``): it reads and writes nothing."""
        return self.stall is not None and self.stall.contains_us(t_us)

    def host_stall_end_us(self) -> int | None:
        """When the stall ends (the host resumes where it was, its clock jumps)."""
        if self.stall is None:
            return None
        return round(self.stall.start_s * 1e6) + round(self.stall.duration_s * 1e6)

    def host_crashed(self, t_us: int) -> bool:
        """True from ``host_crash_at_s`` on: the host never writes again."""
        return self.crash_us is not None and t_us >= self.crash_us

    def host_silent(self, t_us: int) -> bool:
        """Stalled or crashed at ``t_us``."""
        return self.host_stalled(t_us) or self.host_crashed(t_us)

    def line_dead(self, t_us: int) -> bool:
        """True inside ``uart_burst``: nothing crosses the line in either direction."""
        return self.to_mcu.burst is not None and self.to_mcu.burst.contains_us(t_us)

    def recovery_points_us(self) -> list[int]:
        """Ends of the faults the system must recover from by itself (stall end, burst end);
        the MCU reset is reported where it happens."""
        out = []
        if self.stall is not None:
            out.append(self.host_stall_end_us())
        b = self.plan.uart_burst
        if b is not None:
            out.append(round(b.start_s * 1e6) + round(b.duration_s * 1e6))
        return sorted(out)

    # ---- MCU ---------------------------------------------------------------------------------
    def mcu_reset_due(self, prev_us: int, now_us: int) -> bool:
        """True once, for the step (prev_us, now_us] that contains ``mcu_reset_at_s``."""
        r = self.mcu_reset_us
        if r is None or not prev_us < r <= now_us:
            return False
        self.mcu_resets += 1
        return True

    # ---- plant -------------------------------------------------------------------------------
    def wheel_duty(self, left: int, right: int, t_us: int) -> tuple[int, int]:
        """Duties that reach the motors: a failed motor gives nothing from its failure time."""
        if self.motor_fail_us is None or t_us < self.motor_fail_us:
            return left, right
        return (0, right) if self.motor_fail_side == 0 else (left, 0)

    def sonar_range_m(self, index: int, range_m: float | None, t_us: int) -> float | None:
        """A failed sonar hears no echo (None) from its failure time on."""
        if self.sonar_fail_us is not None and index == self.sonar_fail_index \
                and t_us >= self.sonar_fail_us:
            return None
        return range_m

    def encoder_ticks(self, left: int, right: int) -> tuple[int, int]:
        """Cumulative encoder counts after wheel slip."""
        return self.slip.apply(left, right)

    def frame(self, rgb: np.ndarray, t_us: int) -> np.ndarray | None:
        """The frame the host receives (noisy), or None when it is dropped."""
        if self.camera.drop(t_us):
            return None
        return self.camera.noise(rgb, t_us)

    def stats(self) -> dict:
        """What was injected, for the run summary (``faults`` key)."""
        return {"plan": self.plan.as_table(), "uart_to_mcu": self.to_mcu.stats(),
                "uart_to_host": self.to_host.stats(), "camera_frames_dropped":
                self.camera.dropped, "mcu_resets": self.mcu_resets}
