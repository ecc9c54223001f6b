"""The wander's coverage rings (host/coverage.py) and its legs in the search (host.search)."""

from __future__ import annotations

import math

import pytest

from mobigrasp.host import coverage as cv
from mobigrasp.host import search as se


def _dist_to_segment(p, a, b) -> float:
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    n = dx * dx + dy * dy
    u = 0.0 if n == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / n))
    return math.hypot(p[0] - ax - u * dx, p[1] - ay - u * dy)


def _gap_mm(path, radius_mm: int, view_mm: int, step_mm: int = 100) -> float:
    """The largest distance from a point of the disc to the path (the start's look-around
    sees the disc of view_mm, so the path starts at the origin)."""
    worst = 0.0
    for x in range(-radius_mm, radius_mm + 1, step_mm):
        for y in range(-radius_mm, radius_mm + 1, step_mm):
            if x * x + y * y > radius_mm * radius_mm or x * x + y * y <= view_mm * view_mm:
                continue
            worst = max(worst, min(_dist_to_segment((x, y), a, b)
                                   for a, b in zip(path, path[1:], strict=False)))
    return worst


@pytest.mark.parametrize("radius_mm,view_mm", [
    (4500, 1100), (3000, 1100), (2500, 1100), (6000, 900), (4500, 1500), (1500, 1100)])
def test_the_rings_cover_the_disc_with_no_gap_larger_than_the_view(radius_mm, view_mm):
    st = cv.ring_stations(radius_mm, view_mm, 1000)
    assert _gap_mm([(0, 0), *st], radius_mm, view_mm) <= view_mm + 3  # integer mm
    # no ring's sides beyond the disc's inner strip edge (vertices at most 1/cos 30 deg out),
    # none driven twice
    assert max(math.hypot(*s) for s in st) <= (radius_mm - view_mm) * 116 // 100
    assert all(st.count(s) <= 2 for s in st)  # a ring's start is its closing station too
    # stations about a chord apart (the sides of a polygon round the circle)
    assert all(math.dist(a, b) <= 1050 for a, b in zip(st, st[1:], strict=False)
               if abs(math.hypot(*a) - math.hypot(*b)) < 5)


def test_a_small_disc_needs_no_wander_and_a_narrower_strip_would_leave_a_gap():
    assert cv.ring_stations(1100, 1100, 1000) == []
    with pytest.raises(ValueError):
        cv.ring_stations(4500, 0, 1000)
    # the rings laid for a 1.1 m strip leave a gap wider than a 0.7 m one: the check can fail
    assert _gap_mm([(0, 0), *cv.ring_stations(4500, 1100, 1000)], 4500, 700) > 700


def test_the_first_ring_reaches_as_far_as_the_strip_allows():
    """Each ring as far out as its strip meets the one inside it: the first ring's strip,
    beyond the look-around's, reaches ~3 view_mm (within the sagitta of its sides), so that a
    target 2.9 m away is seen on the first ring of the 4.5 m disc (evenly spaced rings, at 1.7
    and 3.4 m, reached 2.8 m with the first)."""
    st = cv.ring_stations(4500, 1100, 1500)
    first = [s for s in st if math.hypot(*s) < 2500]
    assert _gap_mm([(0, 0), *first], 3150, 1100) <= 1100 + 3
    assert max(math.hypot(*s) for s in first) <= 2200 + 3  # its vertices within 2 view_mm
    # the last ring where the disc's edge needs it (unchanged for 002's 2.5 m disc: one ring)
    assert {round(math.hypot(*s)) // 10 for s in cv.ring_stations(2500, 1100, 1500)} == {161}


def test_the_last_ring_lies_edge_mm_inside_the_disc_and_the_first_stays():
    """``edge_mm`` moves the last ring alone (its outward strip reaching the disc's edge from
    there); the rings inside it are laid as before, and no point between them is farther from
    a ring than the strip (the last ring's inner side is checked with its own sweep in
    test_search_wander.py)."""
    def sides(st):
        return sorted({round(math.hypot((a[0] + b[0]) / 2, (a[1] + b[1]) / 2), -1)
                       for a, b in zip(st, st[1:], strict=False)
                       if abs(math.hypot(*a) - math.hypot(*b)) < 5})
    assert sides(cv.ring_stations(4500, 1100, 1500)) == [2070, 3400]
    assert sides(cv.ring_stations(4500, 1100, 1500, 900)) == [2070, 3600]
    assert cv.ring_stations(4500, 1100, 1500, 1100) == cv.ring_stations(4500, 1100, 1500)
    st = cv.ring_stations(4500, 1100, 1500, 900)
    assert _gap_mm([(0, 0), *st], 3600, 1100) <= 1100 + 3
    with pytest.raises(ValueError):
        cv.ring_stations(4500, 1100, 1500, -1)


def test_sides_too_long_for_the_strip_are_refused():
    with pytest.raises(ValueError):
        cv.ring_stations(8000, 300, 8000)  # hexagons too big to step out by a strip


def test_legs_and_frames():
    assert cv.leg_to((0, 0, 0), (1000, 0)) == (0, 1000)
    turn, drive = cv.leg_to((100, 100, 1571), (100, 1100))
    assert abs(turn) <= 2 and drive == 1000
    turn, _ = cv.leg_to((0, 0, 0), (-1000, -10))
    assert -3142 <= turn <= -3100  # behind, a hair to the right: turn right
    assert cv.to_odometry((500, -200, 1571), (1000, 0)) in {(500 + d, 800 + e) for d in (-1, 0)
                                                            for e in (-1, 0, 1)}


def _drive(s: se.ArmSearch, limit_s: int = 2000):
    """Run the search with a base that turns and drives exactly as asked; returns the poses
    where each leg ended and the time."""
    x, y, h, t = 0, 0, 0, 0
    ends = []
    while t < limit_s * 1_000_000:
        c = s.step(t, (x, y, h))
        if s.covered and not s.wandering and not c.drive_mm:
            return ends, t
        if c.drive_mm and s.wandering:
            x += round(c.drive_mm * math.cos(h / 1000))
            y += round(c.drive_mm * math.sin(h / 1000))
            t += 5_000_000
            s.step(t, (x, y, h))
            s.wander_done(t)
            ends.append((x, y))
        elif c.base_turn_mrad:
            h = (h + c.base_turn_mrad + 3142) % 6283 - 3142
            t += 2_000_000
            s.step(t, (x, y, h))
            s.base_turn_done(t)
        else:
            t += 50_000
    raise AssertionError("the search never finished its coverage")


def test_the_search_drives_through_every_station_once_and_terminates():
    p = se.SearchParams(cover_mm=4500)
    s = se.ArmSearch(p, -2100, -800, now_us=0)
    ends, _ = _drive(s)
    want = cv.ring_stations(p.cover_mm, p.view_mm, p.chord_mm)
    assert len(ends) == len(want) and s.wanders == len(want)
    # the rings are laid out from the heading after the look-around: the first leg's
    h0 = math.atan2(ends[0][1], ends[0][0])
    want = [(x * math.cos(h0) - y * math.sin(h0), x * math.sin(h0) + y * math.cos(h0))
            for x, y in want]
    assert all(math.dist(a, b) <= 30 for a, b in zip(ends, want, strict=True))
    # once covered the search looks around where it is: no more legs
    t = 10**10
    for k in range(200):
        c = s.step(t + k * 100_000)
        assert c.drive_mm == 0


def test_a_leg_stopped_short_goes_on_to_the_next_station():
    p = se.SearchParams(cover_mm=3000)
    s = se.ArmSearch(p, -2100, -800, now_us=0)
    t = 0
    while not s.step(t, (0, 0, 0)).drive_mm:
        if s.turning:
            s.base_turn_done(t)  # the look-around's turns, done on the spot
        t += 50_000
    first = s.step(t, (0, 0, 0)).drive_mm
    assert first == cv.ring_stations(3000, 1100, p.chord_mm)[0][0]  # straight ahead
    s.step(t, (500, 0, 0))  # an obstacle: stopped 0.5 m out
    s.wander_done(t)
    c = s.step(t, (500, 0, 0))
    nxt = cv.ring_stations(3000, 1100, p.chord_mm)[1]
    turn, drive = cv.leg_to((500, 0, 0), nxt)
    assert (c.base_turn_mrad, s.turning, s.wandering) == (turn, True, False)
    s.base_turn_done(t)
    assert s.step(t, (500, 0, turn)).drive_mm == drive
