"""The SEARCH wander and the sighting memory of the task (host.task_states uses them).

The wander is the caller's half of host.search's wandering search (000 §II: the robot "firstly
wanders in the environment to search object"): drive straight ahead on odometry for the leg the
search asks, stop short when a front sonar sees something.  The sighting memory lets a sighting
near the edge of the radial symbol's range count when it is seen again at the same place.
Integer mm / us; no I/O and no clock.
"""

from __future__ import annotations

from host.fixedpoint import isqrt


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
