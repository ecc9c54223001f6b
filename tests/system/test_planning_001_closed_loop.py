"""001 in a closed loop, in isolation: plan, follow, sonar every 100 ms, replan when blocked.

A kinematic unicycle among round obstacles, sonars by ray casts over each cone (k_s = 5,
A_g = 1.05 rad, D_e = 2.5 m; 0xFFFF = no echo, as the telemetry sends it). Postconditions: the
base never touches an obstacle (footprint radius 0.17 m), and with obstacles off to the side it
reaches the grasp circle. With obstacles straight ahead 001's planner, with its own parameters,
often finds no feasible curve (eq. (15) marks the centre sub-region whenever the centre sonar
hears an echo, and a_t = v²κ <= 0.1 m/s² at v0 = 0.2 m/s forbids sharp swerves); then the
decision is "stop", which is safe, and the task decides what to do next.
"""

import math

import numpy as np
import pytest

from mobigrasp.host.control.path_follow import PathFollower, Trajectory
from mobigrasp.host.odometry import Pose
from mobigrasp.host.planning.replan import Replanner
from mobigrasp.host.planning.sonar_regions import SonarConfig, sonar_q

CFG = SonarConfig()
FOOTPRINT_M = 0.17


def sonar_mm(x, y, th, obstacles, rays=25):
    out = []
    for k in range(1, CFG.k_s + 1):
        phi = th + sonar_q(CFG).axis_urad(k) / 1e6
        best = CFG.d_e_m
        for a in np.linspace(phi - CFG.a_g_rad / 2, phi + CFG.a_g_rad / 2, rays):
            dx, dy = math.cos(a), math.sin(a)
            for ox, oy, r in obstacles:
                px, py = ox - x, oy - y
                t = px * dx + py * dy
                d2 = px * px + py * py - t * t
                if t > 0 and d2 <= r * r:
                    best = min(best, t - math.sqrt(r * r - d2))
        out.append(int(best * 1000) if best < CFG.d_e_m else 0xFFFF)
    return out


def scenario(seed, side):
    rng = np.random.default_rng(seed)
    dist = rng.uniform(2.5, 4.0)
    obstacles = []
    for _ in range(int(rng.integers(1, 3))):
        ox = rng.uniform(0.6, dist - 0.6)
        if side:  # bearing from the start larger than ~40°
            oy = rng.choice([-1, 1]) * (ox * 0.8 + rng.uniform(0.1, 0.5))
        else:
            oy = rng.uniform(-0.8, 0.8)
        obstacles.append((ox, oy, rng.uniform(0.08, 0.15)))
    return np.array([dist, 0.0]), obstacles


def run(seed, side):
    obj, obstacles = scenario(seed, side)
    x, y, th = 0.0, 0.0, 0.0
    rp = Replanner(obj)
    rp.start(0, (x, y), th, (0.2, 0.0), sonar_mm(x, y, th, obstacles))
    fol = PathFollower(Trajectory.from_curve(rp.curve), 0, 400) if rp.curve else None
    clearance = math.inf
    prev = (x - 0.02, y)
    t = 0
    stopped_cycles = 0
    while t < 90_000_000:
        if t % 100_000 == 0:
            if t > 0:
                vel = ((x - prev[0]) / 0.1, (y - prev[1]) / 0.1)
                dec = rp.update(t, (x, y), th, vel, sonar_mm(x, y, th, obstacles))
                assert dec.ops.time_us() <= 100_000
                if dec.replanned:
                    fol = PathFollower(Trajectory.from_curve(dec.curve), t, 400)
                elif dec.curve is None:
                    fol = None
                    stopped_cycles += 1
            prev = (x, y)
        if fol is None:
            if stopped_cycles > 3:  # no path even slowly: the task must take over
                return "stopped", clearance
            t += 20_000  # standing still until the next sonar reading
            continue
        heading = round(((th + math.pi) % (2 * math.pi) - math.pi) * 1000)
        cmd = fol.step(t, Pose(round(x * 1e6), round(y * 1e6), heading, 0, 0))
        if cmd.done:
            reached = abs(math.hypot(x - obj[0], y - obj[1]) - 0.255) < 0.05
            return ("reached" if reached else "ended elsewhere"), clearance
        vl, vr = cmd.left_mm_s / 1000, cmd.right_mm_s / 1000
        v, w = (vl + vr) / 2, (vr - vl) / 0.3
        x += v * 0.02 * math.cos(th)
        y += v * 0.02 * math.sin(th)
        th += w * 0.02
        for ox, oy, r in obstacles:
            clearance = min(clearance, math.hypot(x - ox, y - oy) - r - FOOTPRINT_M)
        t += 20_000
    return "timeout", clearance


def test_side_obstacles_are_passed_and_the_circle_reached():
    results = [run(seed, side=True) for seed in range(6)]
    assert all(c > 0 for _, c in results)
    assert sum(r == "reached" for r, _ in results) >= 5


def test_obstacles_ahead_never_collide_either_reach_or_stop():
    results = [run(seed, side=False) for seed in range(100, 112)]
    assert all(c > 0 for _, c in results)
    assert {r for r, _ in results} <= {"reached", "stopped"}


@pytest.mark.slow
def test_side_obstacles_40_seeds():
    results = [run(seed, side=True) for seed in range(40)]
    assert all(c > 0 for _, c in results)
    assert sum(r == "reached" for r, _ in results) >= 36
