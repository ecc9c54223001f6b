"""The sonar guard: no drive into what the sonar ring sees (docs/task.md, "No contact").

The ring is 001's (§III.C.2: k_s sonars from -pi/2, right, to pi/2, left, each a cone of A_g);
000 and 002 carry the same ring. While the base would move forward in SEARCH or APPROACH, a
sonar of the ring's front half reading below the safety circle R_r (``r_r_mm``) that is not the
object's own echo (its estimate in that sonar's cone at the range read, ``GUARD_OBJECT_MM``)
stops the base. The base then turns in place toward the middle of the widest run of free
sonars and drives ``GUARD_OUT_MM`` along it (a detour, :func:`drive_detour`), out of R_r, before
the method goes on: 001 plans afresh from there (method001.py); 000's and 002's states go on from
the new pose (:class:`SonarGuard`, run after every step by ``Method.guard_wheels``).

The close approach (ADJUST, and ROUGH_GRASP's drive into the grasp's reach) passes within R_r
of things beside the object on purpose (002's board post stands 0.17 m behind the cylinder's
axis), so it is guarded nearer: a front echo within ``CLOSE_GUARD_MM`` of the ring that is not
the object's (nearer than the estimate by more than ``CLOSE_OBJECT_MM``) stops the base there
(:func:`close_echo`, :func:`close_guard`). A thin thing beside the way (a post 20-60 mm aside of
the front sonar's axis) leaves the cone before the ring comes that near and no sonar sees it
after: the edges of each close echo's arc are remembered on odometry until a later reading sees
through them, and one the footprint would reach within ``CLOSE_SIDE_MM`` of driving on stops
the base too (:func:`remember_echoes`, :func:`side_echo`). Integer mm / mrad; no I/O.
"""

from __future__ import annotations

from typing import Any

from mobigrasp.host.fixedpoint import atan2_mrad, cos_q12, isqrt, sin_q12
from mobigrasp.host.task.drive import wrap_mrad

TURN_TOL_MRAD = 60  # the detour turns to within this of its heading before it drives
DETOUR_STOP_MM = 400  # straight ahead: footprint radius 170 mm + braking and margin
DETOUR_DIAG_MM = 255
GUARD_OBJECT_MM = 150  # an echo this close to the object estimate's range is the object's
GUARD_OUT_MM = 200  # after the guard stopped the base: drive this far toward the free sector
GUARDED_STATES = ("SEARCH", "APPROACH")
CLOSE_GUARD_MM = 30  # ADJUST / the grasp's reach drive: a front echo this near the ring stops
CLOSE_OBJECT_MM = 80  # ... unless in the object's cone at most this much nearer than its centre
CLOSE_REACH_MM = 60  # stopped this near beyond grasp_r_mm: grasp from there, else search again
CLOSE_MEMORY_MM = 250  # a front echo nearer than this (not the object's): its arc's edges kept
CLOSE_SIDE_MM = 12  # ... and one the footprint reaches within this much driving on stops
SIDE_CLEAR_MM = 10  # a kept edge this much nearer than a new reading in its cone is seen through
SIDE_ECHOES = 16  # edges kept at most (the farthest from the base goes first)


def sonar_angles_mrad(n: int) -> list[int]:
    """phi_k of 001 §III.C.2 (k = 1..n evenly from -pi/2, right, to pi/2, left), mrad."""
    return [-1571 + k * 3142 // (n - 1) for k in range(n)] if n >= 2 else []


def widest_free_heading(inp, clear_mm: int) -> int:
    """Odometry heading of the middle of the widest run of neighbouring sonars that read no
    echo or one beyond ``clear_mm``; with none free, a quarter turn left."""
    angles = sonar_angles_mrad(len(inp.sonar_mm))
    best, run = None, []
    for phi, rng in [*zip(angles, inp.sonar_mm, strict=True), (None, 0)]:
        free = phi is not None and (int(rng) <= 0 or int(rng) >= clear_mm)
        if free:
            run.append(phi)
            continue
        if run and (best is None or len(run) > len(best)):
            best = run
        run = []
    if best is None:
        return wrap_mrad(inp.heading_mrad + 1571)
    return wrap_mrad(inp.heading_mrad + (best[0] + best[-1]) // 2)


def free_heading_nearest(inp, xy_mm: tuple, clear_mm: int) -> int | None:
    """Odometry heading of the sonar that reads no echo or one beyond ``clear_mm`` whose
    direction is nearest the bearing of ``xy_mm`` from the base; None when none is free."""
    bearing = atan2_mrad(xy_mm[1] - inp.y_mm, xy_mm[0] - inp.x_mm)
    best = None
    for phi, rng in zip(sonar_angles_mrad(len(inp.sonar_mm)), inp.sonar_mm, strict=True):
        h = wrap_mrad(inp.heading_mrad + phi)
        off = abs(wrap_mrad(h - bearing))
        if int(rng) >= clear_mm and (best is None or off < best[0]):
            best = (off, h)
    return None if best is None else best[1]


def blocked_ahead(sonar_mm: tuple) -> bool:
    """The detour passes close beside obstacles (that is its point): stop only for an echo
    straight ahead within DETOUR_STOP_MM, or at 45 degrees within DETOUR_DIAG_MM (a surface
    point there is DETOUR_DIAG_MM / sqrt(2) = 180 mm aside: the 0.17 m footprint would touch)."""
    n = len(sonar_mm)
    if n < 3:
        return False
    mid = n // 2
    ahead = int(sonar_mm[mid])
    diag = (int(sonar_mm[mid - 1]), int(sonar_mm[mid + 1])) if n >= 5 else ()
    return 0 < ahead < DETOUR_STOP_MM or any(0 < v < DETOUR_DIAG_MM for v in diag)


def object_echo(t: Any, inp: Any, phi: int, rng: int, half_cone: int) -> bool:
    """The object estimate lies in the cone of the sonar at ``phi`` at about range ``rng``."""
    h = inp.heading_mrad + phi
    off = t.p.sonar_offset_mm
    sx = inp.x_mm + (off * cos_q12(h) >> 12)
    sy = inp.y_mm + (off * sin_q12(h) >> 12)
    dx, dy = t.obj[0] - sx, t.obj[1] - sy
    d = isqrt(dx * dx + dy * dy)
    return (abs(wrap_mrad(atan2_mrad(dy, dx) - h)) <= half_cone
            and abs(d - rng) <= GUARD_OBJECT_MM)


def front_echo(t: Any, inp: Any) -> dict | None:
    """The first sonar of the ring's front half (|phi_k| < pi/2) reading below R_r that is
    not the object's own echo, as the trace's ``sonar_guard`` detail; None when there is none."""
    half_cone = t.p.sonar_a_g_mrad // 2
    for phi, rng in zip(sonar_angles_mrad(len(inp.sonar_mm)), inp.sonar_mm, strict=True):
        rng = int(rng)
        if abs(phi) >= 1571 or not 0 < rng < t.p.r_r_mm:
            continue
        if t.obj is not None and object_echo(t, inp, phi, rng, half_cone):
            continue
        return {"phi_mrad": phi, "range_mm": rng, "r_r_mm": t.p.r_r_mm}
    return None


def close_object_echo(t: Any, inp: Any, phi: int, rng: int) -> bool:
    """The echo at ``rng`` of the sonar at ``phi`` is the object's own: the object (its centre
    estimate in that sonar's cone) echoes from its near surface, a radius or so short of the
    centre; something ``CLOSE_OBJECT_MM`` or more nearer than that is in front of it (002's
    board post, 170 mm behind the cylinder's axis, when approached from behind the board)."""
    if t.obj is None:
        return False
    off = t.p.sonar_offset_mm
    h = inp.heading_mrad + phi
    dx = t.obj[0] - inp.x_mm - (off * cos_q12(h) >> 12)
    dy = t.obj[1] - inp.y_mm - (off * sin_q12(h) >> 12)
    return (abs(wrap_mrad(atan2_mrad(dy, dx) - h)) <= t.p.sonar_a_g_mrad // 2
            and rng >= isqrt(dx * dx + dy * dy) - CLOSE_OBJECT_MM)


def close_echo(t: Any, inp: Any) -> dict | None:
    """The first sonar of the ring's front half reading within ``CLOSE_GUARD_MM`` that is not
    the object's own echo (:func:`close_object_echo`), else a kept echo edge the footprint is
    about to reach (:func:`side_echo`). None when there is none."""
    for phi, rng in zip(sonar_angles_mrad(len(inp.sonar_mm)), inp.sonar_mm, strict=True):
        rng = int(rng)
        if abs(phi) >= 1571 or not 0 < rng < CLOSE_GUARD_MM:
            continue
        if close_object_echo(t, inp, phi, rng):
            continue
        return {"phi_mrad": phi, "range_mm": rng, "close_mm": CLOSE_GUARD_MM}
    return side_echo(t, inp)


def remember_echoes(t: Any, inp: Any) -> None:
    """Keep ``t.side_echoes`` (odometry points) up to date with this step's new readings (those
    that differ from the step before's, ``t.sonar_last``). A reading sees through the kept
    points strictly inside its cone ``SIDE_CLEAR_MM`` or more nearer than it (no echo, 0xFFFF:
    all of them), which are dropped. A front-half echo within ``CLOSE_MEMORY_MM`` that is not the
    object's (:func:`close_object_echo`) adds the two edges of its arc: the thing is somewhere
    on the arc, and the +-A_g/2 ends are where it leaves the cone unseen (one of them, or one
    of an earlier echo's as it slid across the cone, is the part of a post the footprint meets
    first). Points farther than the ring plus ``CLOSE_MEMORY_MM`` from the base are
    forgotten; with ``SIDE_ECHOES`` kept, the farthest makes room."""
    n = len(inp.sonar_mm)
    last = t.sonar_last if len(t.sonar_last) == n else (-1,) * n
    t.sonar_last = tuple(map(int, inp.sonar_mm))
    if n < 2 or (not t.side_echoes and t.sonar_last == last):
        return  # nothing kept and no new reading: nothing to drop or add
    off, half_cone = t.p.sonar_offset_mm, t.p.sonar_a_g_mrad // 2
    far = off + CLOSE_MEMORY_MM
    kept = [(x, y) for x, y in t.side_echoes
            if (x - inp.x_mm) ** 2 + (y - inp.y_mm) ** 2 <= far * far]
    for phi, rng, before in zip(sonar_angles_mrad(n), t.sonar_last, last, strict=True):
        if rng == before or rng <= 0:
            continue
        h = inp.heading_mrad + phi
        sx = inp.x_mm + (off * cos_q12(h) >> 12)
        sy = inp.y_mm + (off * sin_q12(h) >> 12)
        free = rng - SIDE_CLEAR_MM
        kept = [(x, y) for x, y in kept
                if not (abs(wrap_mrad(atan2_mrad(y - sy, x - sx) - h)) < half_cone
                        and (x - sx) ** 2 + (y - sy) ** 2 < free * free)]
        if abs(phi) >= 1571 or rng >= CLOSE_MEMORY_MM or close_object_echo(t, inp, phi, rng):
            continue
        for edge in (h - half_cone, h + half_cone):
            if len(kept) >= SIDE_ECHOES:  # the farthest from the base makes room
                kept.remove(max(kept, key=lambda p: (p[0] - inp.x_mm) ** 2
                                + (p[1] - inp.y_mm) ** 2))
            kept.append((sx + (rng * cos_q12(edge) >> 12), sy + (rng * sin_q12(edge) >> 12)))
    t.side_echoes = kept


def side_echo(t: Any, inp: Any) -> dict | None:
    """The kept edge (:func:`remember_echoes`) the footprint (a circle of the ring's radius)
    reaches first driving straight on, when that is within ``CLOSE_SIDE_MM``: its bearing from
    the base and the drive left, as the trace's ``close_guard`` detail; None when there is
    none."""
    r = t.p.sonar_offset_mm
    c, s = cos_q12(inp.heading_mrad), sin_q12(inp.heading_mrad)
    best = None
    for x, y in t.side_echoes:
        dx, dy = x - inp.x_mm, y - inp.y_mm
        ahead, aside = (dx * c + dy * s) >> 12, (dy * c - dx * s) >> 12
        if ahead <= 0 or abs(aside) >= r:
            continue
        left = ahead - isqrt(r * r - aside * aside)
        if left < CLOSE_SIDE_MM and (best is None or left < best[0]):
            best = (left, wrap_mrad(atan2_mrad(dy, dx) - inp.heading_mrad))
    if best is None:
        return None
    return {"phi_mrad": best[1], "range_mm": best[0], "close_mm": CLOSE_SIDE_MM, "side": 1}


def close_guard(t: Any, now: int, inp: Any) -> None:
    """After every step: the kept echo edges brought up to date (:func:`remember_echoes`);
    then in ADJUST, driving forward: a close echo (:func:`close_echo`) or a kept edge the
    footprint is about to reach (:func:`side_echo`) stops the base; the grasp goes on from
    there when the object is within ``CLOSE_REACH_MM`` beyond ``grasp_r_mm`` of the waist
    (ROUGH_GRASP, whose drive into the reach stops at the same echoes), else the object is
    searched for again from here (LOST)."""
    remember_echoes(t, inp)
    if t.state != "ADJUST" or t.wheels[0] + t.wheels[1] <= 0:
        return
    echo = close_echo(t, inp)
    if echo is None:
        return
    t.wheels = (0, 0)
    x, y = t.obj_platform(inp)
    dist = isqrt(x * x + y * y) // 16
    t.note(close_guard={**echo, "object_mm": dist})
    seen = "a kept echo edge" if echo.get("side") else "echo"
    why = (f"{seen} {echo['range_mm']} mm ahead at {echo['phi_mrad']} mrad, "
           f"object {dist} mm away")
    if dist <= t.p.grasp_r_mm + CLOSE_REACH_MM:
        t.go(now, "ROUGH_GRASP", f"close guard: {why}: grasp from here")
    else:
        t.go(now, "LOST", f"close guard: {why}: search again")


def guard_stop(t: Any, inp: Any, states: tuple[str, ...]) -> dict | None:
    """In ``states``, with the base driving forward: a front echo below R_r (:func:`front_echo`)
    stops it and drops the followed path and any plan being made; the echo, or None when
    nothing was stopped."""
    if t.state not in states or t.wheels[0] + t.wheels[1] <= 0:
        return None
    echo = front_echo(t, inp)
    if echo is not None:
        t.wheels = (0, 0)
        t.follower, t.plan_job = None, None  # a plan being made started from a pose left
    return echo


def out_of_r_r(inp: Any, clear_mm: int) -> dict:
    """The detour after a guard stop: toward the widest free sector, ``GUARD_OUT_MM`` long."""
    return {"heading_mrad": widest_free_heading(inp, clear_mm), "drive": True, "from": None,
            "length_mm": GUARD_OUT_MM}


def drive_detour(t: Any, inp: Any, d: dict) -> bool:
    """One step of the detour ``d`` (turn to its heading, then drive its length); True when it
    is over (the wheels stopped).

    A detour whose heading was chosen clear of 001's infeasible regions (``d["checked"]``,
    host.planning.escape) passes beside the obstacle it avoids on purpose: it stops only for
    an echo straight ahead (something new in the way); the fixed diagonal threshold of
    :func:`blocked_ahead` would stop it as soon as it starts."""
    err = wrap_mrad(d["heading_mrad"] - inp.heading_mrad)
    if d["from"] is None and abs(err) > TURN_TOL_MRAD:
        v = t.p.turn_wheel_mmps
        t.wheels = (v, -v) if err < 0 else (-v, v)  # counter-clockwise for err > 0
        return False
    if not d["drive"]:
        t.wheels = (0, 0)
        return True
    if d["from"] is None:
        d["from"] = (inp.x_mm, inp.y_mm)
    dx, dy = inp.x_mm - d["from"][0], inp.y_mm - d["from"][1]
    n = len(inp.sonar_mm)
    if d.get("checked") and n:
        blocked = 0 < int(inp.sonar_mm[n // 2]) < DETOUR_STOP_MM
    else:
        blocked = blocked_ahead(inp.sonar_mm)
    length = d.get("length_mm", t.p.detour_mm)
    if dx * dx + dy * dy >= length * length or blocked:
        t.wheels = (0, 0)
        return True
    t.wheels = (t.p.wander_mmps, t.p.wander_mmps)
    return False


class SonarGuard:
    """The guard of a method without its own planner's detours (000, 002): stop, turn to the
    widest free sector and drive out of R_r, overriding the state's wheels meanwhile; a
    followed path is dropped (the state plans again from the new pose)."""

    def step(self, t: Any, now: int, inp: Any) -> None:
        close_guard(t, now, inp)
        if t.guard_out is not None:
            if t.state not in GUARDED_STATES or drive_detour(t, inp, t.guard_out):
                t.guard_out = None
            return
        echo = guard_stop(t, inp, GUARDED_STATES)
        if echo is None:
            return
        # its heading the middle of the sonars free to detour_clear_mm: it passes beside the
        # echo that stopped the base, so only one straight ahead stops it (with the diagonal
        # threshold, an echo at 45 degrees held the base still, stopped every step)
        t.guard_out = {**out_of_r_r(inp, t.p.detour_clear_mm), "checked": True}
        t.note(sonar_guard={**echo, "turn_to_mrad": t.guard_out["heading_mrad"]})


SONAR_GUARD = SonarGuard()
