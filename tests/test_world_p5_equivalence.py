"""The world's stepping shortcuts of perf round 5 give bit for bit what the general loop gives.

- DcMotor.drive: the cached (target, factor) are target_speed_mps() and decay() (0 when stuck),
  also after any setting is assigned directly (faults, tests).
- DiffDriveBase.run_steps: the motor factors from drive() and the encoder arithmetic skipped for
  a step that leaves the pose unchanged; compared with the loop it replaces (kept here as the
  reference) on worlds that drive, turn, stand, push the target, hit a wall and lose a motor,
  state compared bit for bit after every call.
"""

from __future__ import annotations

import math
import struct
import types

import numpy as np
import pytest

from mcu_sim.world import base as base_mod
from mcu_sim.world.actuators import DcMotor
from mcu_sim.world.scenario import loads_scenario
from mcu_sim.world.world import World

SCENARIO = """
[scenario]
name = "t"
method = "000"
seed = 1
time_limit_s = 60
[robot]
x_m = 0
y_m = 0
heading_rad = 0.3
[target]
kind = "radial-symbol"
x_m = 0.9
y_m = 0.25
heading_rad = 0
[[obstacles]]
shape = "wall"
x_m = 2.0
y_m = -3.0
x2_m = 2.0
y2_m = 3.0
"""


def _reference_run_steps(self, n, dt_us=base_mod.PHYSICS_DT_US):
    """DiffDriveBase.run_steps as it was before perf round 5 (the general loop)."""
    if n <= 0:
        return
    body_p, control_p, space_p = self._ptrs
    tl, tr = self.left.target_speed_mps(), self.right.target_speed_mps()
    kl = 0.0 if self.left.stuck else self.left.decay(dt_us)
    kr = 0.0 if self.right.stuck else self.right.decay(dt_us)
    vl, vr = self.left.speed_mps, self.right.speed_mps
    track, half_track = self.track_m, 0.5 * self.track_m
    dt_s = dt_us * 1e-6
    cos, sin = math.cos, math.sin
    lm, rm = self.left_m, self.right_m
    p = base_mod._GET_POS(body_p)
    x0, y0 = p.x, p.y
    a0 = base_mod._GET_ANGLE(body_p)
    for i in range(n):
        self.steps += 1
        vl = tl + (vl - tl) * kl
        vr = tr + (vr - tr) * kr
        v = 0.5 * (vl + vr)
        base_mod._SET_VEL(control_p, (v * cos(a0), v * sin(a0)))
        base_mod._SET_W(control_p, (vr - vl) / track)
        if i == 0 and self.space_changed:
            self.space.step(dt_s)
            self.space_changed = False
        else:
            base_mod._STEP(space_p, dt_s)
        p = base_mod._GET_POS(body_p)
        x1, y1 = p.x, p.y
        a1 = base_mod._GET_ANGLE(body_p)
        am = 0.5 * (a0 + a1)
        d = (x1 - x0) * cos(am) + (y1 - y0) * sin(am)
        ht = (a1 - a0) * half_track
        lm += d - ht
        rm += d + ht
        x0, y0, a0 = x1, y1, a1
    self.left.speed_mps, self.right.speed_mps = vl, vr
    self.left_m, self.right_m = lm, rm


def _state(w: World) -> bytes:
    b = w.base
    vel = base_mod._lib.cpBodyGetVelocity(b.body._body)
    return struct.pack(
        "<3d4d2d4dq2q", *b.pose(), b.left_m, b.right_m, b.left.speed_mps, b.right.speed_mps,
        vel.x, vel.y, *w.target.pose(), b.steps, *w.encoder_ticks(),
    ) + repr(sorted(w.contacts.counts.items())).encode()


def _schedule(seed: int):
    """(t_us, duties or None, fault) events: drive, turn, stop and stand, reverse, a stuck
    motor, a weak motor; step_to targets at uneven times (1..23 ms apart)."""
    rng = np.random.default_rng(seed)
    t = 0
    duties = [(200, 200), (120, -60), (0, 0), (0, 0), (-90, -150), (255, 180), (0, 0)]
    events = []
    for k, d in enumerate(duties):
        fault = {2: "stuck", 4: "unstuck", 5: "gain"}.get(k)
        events.append((t, d, fault))
        end = t + int(rng.integers(1_500_000, 3_000_000))
        while t < end:
            t += int(rng.integers(1_000, 23_000))
            events.append((t, None, None))
    return events


@pytest.mark.parametrize("seed", [0, 1])
def test_run_steps_equals_the_reference_loop_bit_for_bit(seed):
    fast = World(loads_scenario(SCENARIO, "t.toml"))
    ref = World(loads_scenario(SCENARIO, "t.toml"))
    ref.base.run_steps = types.MethodType(_reference_run_steps, ref.base)
    still_steps = 0
    for t, duty, fault in _schedule(seed):
        for w in (fast, ref):
            if fault == "stuck":
                w.base.left.stuck = True
            elif fault == "unstuck":
                w.base.left.stuck = False
            elif fault == "gain":
                w.base.right.gain = 0.6
            if duty is not None:
                w.set_wheel_duty(*duty)
            before = w.base.pose()
            w.step_to(t)
        still_steps += before == fast.base.pose()
        assert _state(fast) == _state(ref), t
    assert fast.contacts.counts["obstacle"] >= 1 or fast.contacts.counts["target"] >= 1
    assert still_steps > 10  # the shortcut was taken


def test_drive_is_target_and_decay_after_any_setting_changes():
    m = DcMotor()

    def check():
        want = (m.target_speed_mps(), 0.0 if m.stuck else m.decay(1000))
        assert m.drive(1000) == want
        assert m.drive(1000) == want  # cached
        assert m.drive(500) == (m.target_speed_mps(), 0.0 if m.stuck else m.decay(500))

    check()
    m.set_duty(-170)
    check()
    for name, value in (("gain", 0.7), ("supply_v", 9.0), ("max_speed_mps", 0.8),
                        ("tau_s", 0.05), ("stuck", True), ("stuck", False), ("duty", 33)):
        setattr(m, name, value)
        assert getattr(m, name) == value
        check()
