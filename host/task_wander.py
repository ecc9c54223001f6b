"""The SEARCH wander, the sighting memory and the 001 detour of the task (host.task_states).

The wander is the caller's half of host.search's wandering search (000 §II: the robot "firstly
wanders in the environment to search object"): drive straight ahead on odometry for the leg the
search asks, stop short when a front sonar sees something.  The sighting memory lets a sighting
near the edge of the radial symbol's range count when it is seen again at the same place.
The detour (ours, not 001's): when no candidate curve of 001 is feasible from where the robot
stands (obstacles across the way) and the object is too far for the direct close approach, turn
toward the free sonar direction (reading >= ``detour_clear_mm``) nearest the object's bearing and
drive ``detour_mm`` that way, then plan again from there.
Integer mm / us; no I/O and no clock.
"""

from __future__ import annotations

from mobigrasp.host.fixedpoint import atan2_mrad, isqrt

TURN_TOL_MRAD = 60
DETOUR_STOP_MM = 400  # straight ahead: footprint radius 170 mm + braking and margin
DETOUR_DIAG_MM = 255


def _wrap(a: int) -> int:
    return (a + 3142) % 6283 - 3142


def sonar_angles_mrad(n: int) -> list[int]:
    """phi_k of 001 §III.C.2 (k = 1..n evenly from -pi/2, right, to pi/2, left), mrad."""
    return [-1571 + k * 3142 // (n - 1) for k in range(n)] if n >= 2 else []


def start_detour(inp, obj_xy_mm: tuple, clear_mm: int, heading_mrad: int | None = None) -> dict:
    """The detour's heading: ``heading_mrad`` when the caller found one clear of 001's
    infeasible regions (host.planning.escape), else the free sonar direction nearest the
    object's bearing; with none free a quarter turn left (the next sonar sweep decides again)."""
    if heading_mrad is not None:
        return {"heading_mrad": _wrap(int(heading_mrad)), "drive": True, "from": None,
                "checked": True}
    bearing = atan2_mrad(obj_xy_mm[1] - inp.y_mm, obj_xy_mm[0] - inp.x_mm)
    best = None
    for phi, rng in zip(sonar_angles_mrad(len(inp.sonar_mm)), inp.sonar_mm, strict=True):
        h = _wrap(inp.heading_mrad + phi)
        off = abs(_wrap(h - bearing))
        if int(rng) >= clear_mm and (best is None or off < best[0]):
            best = (off, h)
    if best is None:
        return {"heading_mrad": _wrap(inp.heading_mrad + 1571), "drive": False, "from": None}
    return {"heading_mrad": best[1], "drive": True, "from": None}


def seen_there_before(task) -> bool:
    """000/001: a sighting that could not be confirmed, seen again at the same odometry place
    (within ``sighting_match_mm``), is the object: near the edge of the symbol's range
    (~1.1 m) single frames come and go, and two from different poses agreeing are
    evidence enough to approach (the approach sees it better as it comes closer)."""
    if task.sighting is None or task.obj is None:
        return False
    dx, dy = task.obj[0] - task.sighting[0], task.obj[1] - task.sighting[1]
    return dx * dx + dy * dy <= task.p.sighting_match_mm * task.p.sighting_match_mm


def wander_step(task, now: int, inp, cmd) -> None:
    """Drive the search's wander straight ahead on odometry (000 §II "wanders in the
    environment"); stop short when a front sonar sees something within wander_clear_mm."""
    if task.wander_from is None:
        task.wander_from = (inp.x_mm, inp.y_mm)
        task.note(wander_mm=cmd.drive_mm, search_cycle=cmd.cycle)
    dx, dy = inp.x_mm - task.wander_from[0], inp.y_mm - task.wander_from[1]
    n = len(inp.sonar_mm)
    front = [int(v) for v in inp.sonar_mm[max(0, n // 2 - 1):n // 2 + 2]] if n else []
    blocked = any(0 < v < task.p.wander_clear_mm for v in front)
    if dx * dx + dy * dy >= cmd.drive_mm * cmd.drive_mm or blocked:
        task.note(wander_done_mm=isqrt(dx * dx + dy * dy), wander_blocked=blocked)
        task.search.wander_done(now)
        task.wander_from = None
        task.wheels = (0, 0)
    else:
        task.wheels = (task.p.wander_mmps, task.p.wander_mmps)


def _blocked_ahead(sonar_mm: tuple) -> bool:
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


def detour_step(task, inp) -> bool:
    """One step of the detour; True when it is over (the caller plans again).

    A detour whose heading was chosen clear of 001's infeasible regions (``d["checked"]``,
    host.planning.escape) passes beside the obstacle it avoids on purpose: it stops only for
    an echo straight ahead (something new in the way); the fixed diagonal threshold of
    :func:`_blocked_ahead` would stop it as soon as it starts."""
    d = task.detour
    err = _wrap(d["heading_mrad"] - inp.heading_mrad)
    if d["from"] is None and abs(err) > TURN_TOL_MRAD:
        v = task.p.turn_wheel_mmps
        task.wheels = (v, -v) if err < 0 else (-v, v)  # counter-clockwise for err > 0
        return False
    if not d["drive"]:
        task.wheels = (0, 0)
        return True
    if d["from"] is None:
        d["from"] = (inp.x_mm, inp.y_mm)
    dx, dy = inp.x_mm - d["from"][0], inp.y_mm - d["from"][1]
    n = len(inp.sonar_mm)
    if d.get("checked") and n:
        blocked = 0 < int(inp.sonar_mm[n // 2]) < DETOUR_STOP_MM
    else:
        blocked = _blocked_ahead(inp.sonar_mm)
    if dx * dx + dy * dy >= task.p.detour_mm * task.p.detour_mm or blocked:
        task.wheels = (0, 0)
        return True
    task.wheels = (task.p.wander_mmps, task.p.wander_mmps)
    return False
