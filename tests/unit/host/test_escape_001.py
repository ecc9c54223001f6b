"""001 near an obstacle: eq. (16) cut to the grown echo arc, the detour's way out, its drive."""

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples
from region_ref import Ref, grown_m, inside_q, region_m

from mobigrasp.host.planning.escape import escape_heading, segment_clear
from mobigrasp.host.planning.sonar_regions import InfeasibleRegion, SonarConfig, infeasible_regions
from mobigrasp.host.task import TaskInputs, TaskParams

# an echo 0.41 m from the centre in the narrow overlap of S_3 and S_4
NEAR = (0.0, 0.0, 0.26, 0.525, 0.406, 0.2)


def _arc_distance(reg: InfeasibleRegion, x: float, y: float) -> float:
    f = Ref(reg)
    a = np.linspace(f.lo_rad, f.hi_rad, 2001)
    return float(np.min(np.hypot(x - f.eta_m * np.cos(a), y - f.eta_m * np.sin(a))))


def test_literal_wedge_covers_points_beside_the_robot_and_the_bound_frees_them():
    literal = region_m(*NEAR)
    bounded = region_m(*NEAR, arc_bound=True)
    # 0.25 m straight behind the robot, away from the echo: 0.65 m from the echo arc; and
    # 0.21 m from the centre, 75 degrees clockwise of the echo
    for d, off in ((0.25, math.pi), (0.21, -math.radians(75))):
        x, y = d * math.cos(0.3925 + off), d * math.sin(0.3925 + off)
        assert _arc_distance(literal, x, y) > 0.3
        # eq. (16) as written: the strip through the robot
        assert Ref(literal).contains(x, y) and inside_q([literal], x, y)
        assert not Ref(bounded).contains(x, y)
        assert not inside_q([bounded], x, y)
    # on the echo itself both agree
    assert inside_q([literal], 0.35, 0.2) and inside_q([bounded], 0.35, 0.2)


@examples(150)
@given(st.floats(0.3, 2.4), st.floats(0.05, 0.6), st.floats(-3.1, 3.1), st.floats(0.0, 1.0),
       st.floats(-math.pi, math.pi), st.floats(0.0, 0.2))
def test_the_bound_never_frees_a_point_within_r_r_of_the_echo(eta, width, mid, along, dirn, r):
    """In floats within R_r; in the integers within R_r less 3 mm."""
    reg = region_m(0.3, -0.2, mid - width / 2, mid + width / 2, eta, 0.2, arc_bound=True)
    literal = dataclasses.replace(reg, arc_bound=False)
    f = Ref(reg)
    ang = f.lo_rad + along * (f.hi_rad - f.lo_rad)
    for within, bounded, plain in ((0.999 * r, Ref(reg).contains, Ref(literal).contains),
                                   (max(0.0, r - 0.003), lambda x, y: inside_q([reg], x, y),
                                    lambda x, y: inside_q([literal], x, y))):
        x = f.ox + f.eta_m * math.cos(ang) + within * math.cos(dirn)
        y = f.oy + f.eta_m * math.sin(ang) + within * math.sin(dirn)
        if plain(x, y):  # the cut only removes points, never adds
            assert bounded(x, y)
        assert not (bounded(x, y) and not plain(x, y))


def test_vectorised_test_matches_the_single_region_test_with_the_bound():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    scan = infeasible_regions(cfg, (0.1, 0.2), 0.4, [300, 700, 236, 225, 2600])
    assert scan.regions and all(r.arc_bound for r in scan.regions)
    rng = np.random.default_rng(7)
    x, y = rng.uniform(-1.5, 1.7, 4000), rng.uniform(-1.4, 1.8, 4000)
    ref = np.zeros(x.shape, dtype=bool)
    for reg in scan.regions:
        ref |= inside_q([reg], x, y)
    assert np.array_equal(inside_q(scan.regions, x, y), ref)


def test_escape_heading_is_the_clear_one_nearest_the_object():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    # facing +x, the object straight ahead, an echo front-left 0.23 m from the ring
    regions = infeasible_regions(cfg, (0.0, 0.0), 0.0, [65535, 65535, 225, 236, 65535]).regions
    head, ops = escape_heading(regions, (0.0, 0.0), 0.0, 0.0, 0.6, 0.1)
    assert head is not None and head < -0.2  # away from the echo, to the right
    assert segment_clear([_grown(r, 0.1) for r in regions], (0.0, 0.0), head, 0.6)[0]
    nearer = head + math.pi / 12  # the next heading toward the object is not clear
    assert not segment_clear([_grown(r, 0.1) for r in regions], (0.0, 0.0), nearer, 0.6)[0]
    assert ops.time_us() > 0
    assert segment_clear(regions, (0.0, 0.0), 0.0, 0.6)[0] is False
    # echoes close on every sonar: no way out within the ring's view
    walled = infeasible_regions(cfg, (0.0, 0.0), 0.0, [150] * 5).regions
    assert escape_heading(walled, (0.0, 0.0), 0.0, 0.0, 0.6)[0] is None


def _grown(reg: InfeasibleRegion, m: float) -> InfeasibleRegion:
    return grown_m(reg, m)


def test_checked_detour_passes_beside_an_echo_and_stops_for_one_ahead():
    from mobigrasp.host.task.method001 import RULES, State001, detour_heading

    p = TaskParams.for_method("001")
    d = detour_heading(TaskInputs(sonar_mm=(65535,) * 5), (1500, 0), 900, heading_mrad=-900)
    assert d == {"heading_mrad": -900, "drive": True, "from": None, "checked": True}
    task = SimpleNamespace(p=p, wheels=None, ms=State001(detour=d))
    side = (65535, 65535, 65535, 220, 240)  # the obstacle beside it, front-left and left
    assert not RULES.detour_step(task, TaskInputs(heading_mrad=-900, sonar_mm=side))
    assert task.wheels == (p.wander_mmps, p.wander_mmps)
    # the unchecked detour stops for the same diagonal echo at once
    task.ms.detour = {"heading_mrad": -900, "drive": True, "from": None}
    assert RULES.detour_step(task, TaskInputs(heading_mrad=-900, sonar_mm=side))
    # something straight ahead stops a checked one too
    task.ms.detour = dict(d)
    assert RULES.detour_step(task, TaskInputs(heading_mrad=-900,
                                              sonar_mm=(65535, 65535, 300, 65535, 65535)))
    assert task.wheels == (0, 0)


def test_a_robot_already_too_close_may_leave_but_not_go_further_in():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    # an echo 0.1 m from the ring straight ahead: the robot stands inside its region grown by
    # the detour's 0.1 m margin
    regions = [_grown(r, 0.1) for r in infeasible_regions(
        cfg, (0.0, 0.0), 0.0, [65535, 65535, 100, 65535, 65535]).regions]
    assert any(inside_q([r], 0.0, 0.0) for r in regions)
    assert segment_clear(regions, (0.0, 0.0), math.pi, 0.5, leave_ok=True)[0]  # straight back
    assert not segment_clear(regions, (0.0, 0.0), math.pi, 0.5)[0]
    assert not segment_clear(regions, (0.0, 0.0), 0.0, 0.5, leave_ok=True)[0]  # further in
    head, _ = escape_heading(regions, (0.0, 0.0), 0.0, 0.0, 0.6)
    assert head is not None and abs(head) >= 1.0  # sideways, away from the echo


def test_a_detour_keeps_to_the_side_of_the_first_one():
    cfg = SonarConfig(sensor_offset_m=0.17, shared_echo_tol_m=0.13, arc_angle_bound=True)
    # a wall-like echo straight ahead: both sides are open, the right one slightly nearer
    regions = infeasible_regions(cfg, (0.0, 0.0), 0.0, [65535, 65535, 250, 65535, 65535]).regions
    free, _ = escape_heading(regions, (0.0, 0.0), 0.0, -0.05, 0.6, 0.1)
    left, _ = escape_heading(regions, (0.0, 0.0), 0.0, -0.05, 0.6, 0.1, side=1)
    right, _ = escape_heading(regions, (0.0, 0.0), 0.0, -0.05, 0.6, 0.1, side=-1)
    assert free is not None and free < -0.05  # nearest the goal: right of it
    assert right == free
    assert left is not None and left > -0.05  # kept left although the right is nearer
    assert abs(left + 0.05) > abs(free + 0.05)
