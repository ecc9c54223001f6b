"""Object search with the eye-in-hand camera, 000 §III.B.2 Fig. 5 and §III.A.

The paper's pattern (``dense_cycles`` >= 1): the wrist pitch theta2 oscillates over
[theta2_min, theta2_max] = [-2.8, -2.1] rad in steps of d_theta2 = 0.06 rad (000 §IV); for each
theta2 the waist theta5 sweeps from one end of [theta5_min, theta5_max] = [-0.8, 0.8] rad to the
other (boustrophedon: the next sweep goes back), in steps of d_theta5 (ours: 0.2 rad, under the
0.51 rad horizontal field of view at f = 611 px).
The search starts from the joints at hand (theta2s, theta5s of Fig. 5): the first sweep runs
from theta5s to the far end, theta2 first climbs to theta2_max, then the levels below theta2s
are visited down to theta2_min; every level is swept once per cycle.  When a whole cycle finds
nothing the base turns by a fixed angle (60 degrees here) and a new cycle starts from the other
end of the theta2 range.  theta3, theta4 hold a search posture (parameters) during the search.

Wandering (000 §II: the robot "firstly wanders in the environment to search object"): the radial
symbol on the object's top is measurable only to about 1.1 m from the arm camera, so once the base
has looked all around (``turns_per_wander`` cycles) and found nothing, the search asks the caller
to turn and drive to the next station of a coverage pattern (the caller stops early when a front
sonar sees something; the leg after one stopped short aims at the next station from where the
base is). With ``cover_mm`` > 0 (default) the stations lie on concentric rings around the start
(host/coverage.py) spaced by twice ``view_mm``, the half-width of the strip the sweeping camera
sees while driving: the disc of radius ``cover_mm`` is seen once, the rings are driven once, and
then the search looks around where it is (``covered``). ``cover_mm`` = 0 keeps an expanding
square spiral of legs ``wander_mm * (1 + k // 2)`` (leg k from 0), each look-around turning the
base by 270 degrees.
Sweeping wander (``wander_sweep`` = 1, default): while driving, the waist sweeps
+-``wander_theta5_mrad`` (1.4 rad, the waist servo's range, wider than the paper's +-0.8 rad of
the search at a stop, so that the camera also looks abeam) at the far level
``coarse_theta2_mrad[0]`` (boustrophedon, poses ``wander_d_theta5_mrad`` apart, each held for
the servo travel and ``wander_frames_per_pose`` frames): the drive sees a strip on both sides (the
level sees 0.52-1.1 m; how wide the strip is depends on the sweep's period against the speed,
docs/task.md "000: the sweep while driving"); ground nearer than 0.52 m ahead was seen earlier
further ahead. A ring's leg that keeps ``outward_from_mm`` (> 0) from the start sweeps the side
away from it alone, and ``outward_inward_mrad`` across (the ring inside saw the inner side);
the last ring lies ``edge_mm`` inside ``cover_mm`` (0: ``view_mm``), where that one-sided sweep
reaches the disc's edge (docs/task.md "000: the last ring nearer the edge").
A look-around costs ~30 s for a 1.1 m disk
(3.8 m2), a drive 0.4 m2/s: so after the first look-around at the start the wander stops only to
turn the base toward the next station (``stop_cycles`` = 0), and ``stop_cycles`` > 0 looks around
that many cycles at each stop instead.
``wander_sweep`` = 0 holds the camera left (docs/cosim.md "Measured", T10: a target
1.8-2.4 m away was not found in 150 s of search).
Cycles after the first ``dense_cycles`` (the paper's d_theta2; 0 by default) visit only the
theta2 levels in ``coarse_theta2_mrad``; turns after the first are ``coarse_base_turn_mrad``.
The search after the object was lost near it (000's ADJUST, host/task/method000.py
``lost_search``) has ``dense_cycles`` >= 1: the paper's pattern, with the platform stopped.
Why: with the camera ~0.29 m up, f = 611 px and 240 rows (0.39 rad vertical field), the levels
-2.25, -2.5, -2.75 rad see the object's top from 0.52 m outward, at 0.28-0.86 m and at
0.17-0.4 m; a theta5 sweep over +-0.8 rad with the 0.51 rad horizontal field spans 2.1 rad, so
90 degree turns still overlap.  At the paper's 0.06 rad step a cycle takes ~19 s and a full turn
over two minutes; a coarse cycle takes ~5 s (plus the turn).

Each pose is held for a dwell long enough for the servo travel and ``frames_per_pose`` camera
frames (2 frames at 15 fps = 133 ms by default).  Time is simulated: the caller passes now_us.
"""

from __future__ import annotations

from dataclasses import dataclass

from mobigrasp.host.coverage import leg_to, ring_stations, to_odometry

FRAME_PERIOD_US = 66_667  # 15 fps
LEG_TURN_MIN_MRAD = 35  # a leg whose heading is off by less starts without a turn
LEG_TURN_MAX_MRAD = 3000  # a turn toward a station behind is cut here (the caller wraps at pi)


@dataclass(frozen=True)
class SearchParams:
    """Search pattern in mrad (000 §IV values) and timing in simulated us."""

    theta2_min_mrad: int = -2800
    theta2_max_mrad: int = -2100
    d_theta2_mrad: int = 60
    theta5_min_mrad: int = -800
    theta5_max_mrad: int = 800
    d_theta5_mrad: int = 200
    theta3_mrad: int = -200  # search posture of the elbow and shoulder: with theta2 in the range
    theta4_mrad: int = 2300  # above, alpha = theta2 + 2.1 rad looks 0..0.7 rad below horizontal
    base_turn_mrad: int = 1047  # 60 degrees, counter-clockwise (left)
    coarse_theta2_mrad: tuple = (-2250, -2500, -2750)  # levels of the cycles after the first
    coarse_base_turn_mrad: int = 1571  # turns after the first: 90 degrees
    dense_cycles: int = 0  # first cycles at the paper's d_theta2 (1 = the paper's first look)
    turns_per_wander: int = 4  # cycles per look-around (headings 0, 60, 150, 240 degrees)
    wander_mm: int = 1800  # first leg of the square spiral (cover_mm 0); 0 = never wander
    wander_sweep: int = 1  # 1: the waist sweeps at the far level while driving; 0: looks left
    wander_theta5_mrad: int = 1400  # the sweep while driving spans +- this (the waist's limit)
    stop_cycles: int = 0  # cycles at each wander stop (0: turn coarse_base_turn and drive on)
    frames_per_pose: int = 2
    frame_period_us: int = FRAME_PERIOD_US
    servo_speed_mrad_per_s: int = 5000  # hobby servo, about 0.2 s per 60 degrees
    cover_mm: int = 4500  # the wander covers this disc by host.coverage's rings (0: square)
    view_mm: int = 1100  # half-width of the strip the wander's sweep sees (ring spacing / 2)
    chord_mm: int = 1500  # spacing of the rings' stations (a stop and a turn at each)
    wander_frames_per_pose: int = 2  # frames per waist pose of the sweep while driving
    wander_d_theta5_mrad: int = 200  # waist step of the sweep while driving
    outward_from_mm: int = 0  # a ring's leg this far from the start sweeps outward (0: never)
    outward_inward_mrad: int = 700  # ... and this far across to the inner side
    round_tries: int = 0  # a leg sweeping outward alone (the last ring) stopped by an
    # obstacle goes round it and aims at its station again, at most this often until a leg
    # ends unblocked (0: the next station at once, as every other leg)
    edge_mm: int = 0  # the last ring this far inside cover_mm (0: view_mm; host.coverage)

    def __post_init__(self) -> None:
        if self.theta2_min_mrad >= self.theta2_max_mrad:
            raise ValueError("theta2_min_mrad must be below theta2_max_mrad")
        if self.theta5_min_mrad >= self.theta5_max_mrad:
            raise ValueError("theta5_min_mrad must be below theta5_max_mrad")
        if not self.coarse_theta2_mrad:
            raise ValueError("coarse_theta2_mrad must hold at least one theta2 level")
        # levels outside [theta2_min, theta2_max] (a narrowed range) are clamped into it
        lo, hi = self.theta2_min_mrad, self.theta2_max_mrad
        levels = tuple(dict.fromkeys(min(max(int(v), lo), hi) for v in self.coarse_theta2_mrad))
        object.__setattr__(self, "coarse_theta2_mrad", levels)
        if self.wander_sweep not in (0, 1) or self.stop_cycles < 0:
            raise ValueError(f"wander_sweep must be 0 or 1 and stop_cycles >= 0, got "
                             f"{self.wander_sweep}, {self.stop_cycles}")
        if self.cover_mm < 0 or self.view_mm <= 0 or self.chord_mm <= 0 or self.edge_mm < 0:
            raise ValueError(f"cover_mm and edge_mm must be >= 0, view_mm and chord_mm > 0, got "
                             f"{self.cover_mm}, {self.edge_mm}, {self.view_mm}, {self.chord_mm}")
        if self.wander_mm < 0 or self.dense_cycles < 0:
            raise ValueError(f"wander_mm and dense_cycles must be >= 0, got {self.wander_mm}, "
                             f"{self.dense_cycles}")
        if self.round_tries < 0:
            raise ValueError(f"round_tries must be >= 0, got {self.round_tries}")
        if self.outward_from_mm < 0 or not 0 <= self.outward_inward_mrad < self.wander_theta5_mrad:
            raise ValueError(f"outward_from_mm must be >= 0 and outward_inward_mrad in [0, "
                             f"wander_theta5_mrad), got {self.outward_from_mm}, "
                             f"{self.outward_inward_mrad}")
        for name in ("d_theta2_mrad", "d_theta5_mrad", "frames_per_pose", "frame_period_us",
                     "wander_theta5_mrad", "wander_frames_per_pose", "wander_d_theta5_mrad",
                     "servo_speed_mrad_per_s", "coarse_base_turn_mrad", "turns_per_wander"):
            if getattr(self, name) <= 0:
                raise ValueError(f"{name} must be > 0, got {getattr(self, name)}")


@dataclass(frozen=True)
class SearchCommand:
    """What the search wants now: joint targets, and a base turn (0 = none) to perform."""

    theta2_mrad: int
    theta3_mrad: int
    theta4_mrad: int
    theta5_mrad: int
    base_turn_mrad: int
    pose_index: int  # index in the current cycle
    cycle: int  # completed cycles (= base turns + wanders requested)
    drive_mm: int = 0  # a wander: drive this far straight ahead (0 = none)


def _levels(lo: int, hi: int, step: int, start: int, upward: bool) -> list[int]:
    """theta2 levels of one cycle from ``start``: toward one end, then the rest to the other."""
    start = min(max(start, lo), hi)
    if upward:
        first = list(range(start, hi, step)) + [hi]
        rest = list(range(start - step, lo, -step)) + ([lo] if start != lo else [])
    else:
        first = list(range(start, lo, -step)) + [lo]
        rest = list(range(start + step, hi, step)) + ([hi] if start != hi else [])
    seen: list[int] = []
    for v in first + rest:
        if v not in seen:
            seen.append(v)
    return seen


def _boustrophedon(up: list[int]) -> list[int]:
    """One way, then back without the ends: the poses of a sweep to and fro, cyclic."""
    return up + up[-2:0:-1]


def _sweep(lo: int, hi: int, step: int, frm: int, to_hi: bool) -> list[int]:
    frm = min(max(frm, lo), hi)
    if to_hi:
        return list(range(frm, hi, step)) + [hi]
    return list(range(frm, lo, -step)) + [lo]


def search_cycle(params: SearchParams, theta2_start_mrad: int, theta5_start_mrad: int,
                 upward: bool = True, coarse: bool = False) -> list[tuple[int, int]]:
    """All (theta2, theta5) poses of one search cycle, in order (Fig. 5 of 000); ``coarse``
    visits only the levels ``coarse_theta2_mrad``, nearest to ``theta2_start_mrad`` first."""
    p = params
    poses: list[tuple[int, int]] = []
    th5 = min(max(theta5_start_mrad, p.theta5_min_mrad), p.theta5_max_mrad)
    # first sweep toward the far end from theta5s
    to_hi = (th5 - p.theta5_min_mrad) <= (p.theta5_max_mrad - th5)
    if coarse:
        levels = sorted(set(p.coarse_theta2_mrad))
        if abs(levels[-1] - theta2_start_mrad) < abs(levels[0] - theta2_start_mrad):
            levels.reverse()
        if len(levels) == 1 and p.theta5_min_mrad < th5 < p.theta5_max_mrad:
            levels *= 2  # one sweep from the middle sees only one side: come back over it
    else:
        levels = _levels(p.theta2_min_mrad, p.theta2_max_mrad, p.d_theta2_mrad,
                         theta2_start_mrad, upward)
    for th2 in levels:
        sweep = _sweep(p.theta5_min_mrad, p.theta5_max_mrad, p.d_theta5_mrad, th5, to_hi)
        poses.extend((th2, t5) for t5 in sweep)
        th5 = sweep[-1]
        to_hi = not to_hi
    return poses


class ArmSearch:
    """The search as a state object over simulated time.

    ``step(now_us)`` returns the current :class:`SearchCommand`; after a cycle it carries a
    ``base_turn_mrad`` request until the caller reports :meth:`base_turn_done`, or after every
    ``turns_per_wander``-th cycle a ``drive_mm`` request (a wander) until the caller reports
    :meth:`wander_done`.
    """

    def __init__(self, params: SearchParams, theta2_start_mrad: int, theta5_start_mrad: int,
                 now_us: int) -> None:
        self.params = params
        self.cycle = 0
        self._upward = True
        self._poses = search_cycle(params, theta2_start_mrad, theta5_start_mrad, True,
                                   coarse=params.dense_cycles <= 0)
        self._index = 0
        self._prev = (theta2_start_mrad, theta5_start_mrad)
        self._pose_start_us = int(now_us)
        self._turning = False
        self._wandering = False
        self._corner = False  # turning at a wander stop: the next leg follows (stop_cycles 0)
        self._cycles_here = 0  # cycles completed at this place
        self.wanders = 0
        p = params
        w, d, c = p.wander_theta5_mrad, p.wander_d_theta5_mrad, p.outward_inward_mrad
        # waist poses of the sweeping wander, cyclic: both sides, the left or the right side
        # alone (and outward_inward_mrad across)
        self._wsweeps = {0: _boustrophedon(list(range(-w, w, d)) + [w]),
                         1: _boustrophedon(list(range(w, -c, -d)) + [-c]),
                         -1: _boustrophedon(list(range(-w, c, d)) + [c])}
        self._wsweep = self._wsweeps[0]
        self._windex = 0
        self._wpose = (p.coarse_theta2_mrad[0], p.theta5_max_mrad)
        self._pose = (0, 0, 0)  # the base's odometry pose as last reported to step()
        self._origin = (0, 0)  # the rings' centre in odometry (where the first leg starts)
        self._stations: list[tuple[int, int]] | None = None  # the rings, in odometry
        self._station = 0
        self._leg = (0, 0)  # turn_mrad, drive_mm of the leg toward the next station
        self._rounds = 0  # drives round an obstacle since a leg last ended unblocked
        self.covered = False  # the rings are done: the disc of cover_mm has been seen

    def dwell_us(self, frm: tuple[int, int], to: tuple[int, int], frames: int = 0) -> int:
        """Servo travel of the larger joint move plus the frames to look (``frames`` 0: the
        search's ``frames_per_pose``)."""
        p = self.params
        travel = max(abs(frm[0] - to[0]), abs(frm[1] - to[1]))
        return travel * 1_000_000 // p.servo_speed_mrad_per_s + (frames or p.frames_per_pose) \
            * p.frame_period_us

    def _command(self, turn: int, drive: int = 0) -> SearchCommand:
        th2, th5 = self._poses[self._index]
        p = self.params
        return SearchCommand(th2, p.theta3_mrad, p.theta4_mrad, th5, turn, self._index,
                             self.cycle, drive)

    def _start_wander(self, now_us: int, at: tuple[int, int]) -> None:
        """Drive the next leg; the sweep starts at the waist pose nearest ``at``."""
        self._wandering, self._turning, self._corner = True, False, False
        if self.params.wander_sweep:
            self._wsweep = self._wsweeps[self._outward_side()]
            self._windex = min(range(len(self._wsweep)),
                               key=lambda k: abs(self._wsweep[k] - at[1]))
            self._wpose = (self.params.coarse_theta2_mrad[0], self._wsweep[self._windex])
            self._pose_start_us = int(now_us)
            self._prev = at

    def _start_leg(self, now_us: int, at: tuple[int, int]) -> None:
        """Turn toward the next station of the coverage rings (host.coverage), then drive to
        it; the rings are laid out from the pose where the first leg starts. Past the last
        station the search looks around where it is (``covered``)."""
        p = self.params
        if self._stations is None:
            self._origin = self._pose[:2]
            self._stations = [to_odometry(self._pose, xy) for xy in
                              ring_stations(p.cover_mm, p.view_mm, p.chord_mm, p.edge_mm)]
        while self._station < len(self._stations):
            turn, drive = leg_to(self._pose, self._stations[self._station])
            if drive >= p.chord_mm // 4:
                break
            self._station += 1  # there already
        else:
            self.covered = True
            self._turning = True
            return
        self._leg = (max(-LEG_TURN_MAX_MRAD, min(LEG_TURN_MAX_MRAD, turn)), drive)
        if abs(turn) < LEG_TURN_MIN_MRAD:
            self._start_wander(now_us, at)
        else:
            self._wandering, self._turning, self._corner = False, True, True
            self._wpose = at

    def _outward_side(self) -> int:
        """The side the sweep looks to alone on this leg: on a ring's leg that keeps at least
        ``outward_from_mm`` from the rings' centre (the ground inside it was seen from the ring
        inside), the side away from the centre (1 left, -1 right); else 0, both sides."""
        p = self.params
        if not (p.outward_from_mm and p.cover_mm and self._stations
                and self._station < len(self._stations)):
            return 0
        (px, py), (sx, sy), (ox, oy) = self._pose[:2], self._stations[self._station], self._origin
        lx, ly, ax, ay = sx - px, sy - py, ox - px, oy - py
        cross = lx * ay - ly * ax  # > 0: the centre lies left of the leg
        along, length2 = lx * ax + ly * ay, lx * lx + ly * ly
        if along <= 0 or length2 == 0:  # the leg's nearest point to the centre is its start
            near2 = ax * ax + ay * ay
        elif along >= length2:  # its end
            near2 = (ox - sx) ** 2 + (oy - sy) ** 2
        else:  # the centre's foot on the leg
            near2 = cross * cross // length2
        if near2 < p.outward_from_mm * p.outward_from_mm:
            return 0
        return -1 if cross > 0 else 1

    def _wander_pose(self, now_us: int) -> tuple[int, int]:
        """The camera while driving: left (``wander_sweep`` 0) or the far level's sweep."""
        p = self.params
        if not p.wander_sweep:
            return p.coarse_theta2_mrad[0], p.theta5_max_mrad
        frames = p.wander_frames_per_pose
        while now_us - self._pose_start_us >= self.dwell_us(self._prev, self._wpose, frames):
            self._pose_start_us += self.dwell_us(self._prev, self._wpose, frames)
            self._prev = self._wpose
            self._windex = (self._windex + 1) % len(self._wsweep)
            self._wpose = (p.coarse_theta2_mrad[0], self._wsweep[self._windex])
        return self._wpose

    def _moving_command(self, now_us: int) -> SearchCommand:
        p = self.params
        if self._wandering:
            th2, th5 = self._wander_pose(now_us)
            drive = self._leg[1] if p.cover_mm else p.wander_mm * (1 + self.wanders // 2)
            return SearchCommand(th2, p.theta3_mrad, p.theta4_mrad, th5, 0, self._index,
                                 self.cycle, drive)
        if self._corner:  # the arm holds the last wander pose while the base turns
            turn = self._leg[0] if p.cover_mm else p.coarse_base_turn_mrad
            return SearchCommand(self._wpose[0], p.theta3_mrad, p.theta4_mrad, self._wpose[1],
                                 turn, self._index, self.cycle)
        return self._command(p.base_turn_mrad if self.cycle <= 1 else p.coarse_base_turn_mrad)

    def step(self, now_us: int, pose: tuple[int, int, int] | None = None) -> SearchCommand:
        """Advance the pattern to ``now_us`` and return the command in force; ``pose`` is the
        base's odometry (x_mm, y_mm, heading_mrad), which the coverage rings' legs need."""
        if pose is not None:
            self._pose = (int(pose[0]), int(pose[1]), int(pose[2]))
        if self._turning or self._wandering:
            return self._moving_command(now_us)
        while now_us - self._pose_start_us >= self.dwell_us(self._prev, self._poses[self._index]):
            self._pose_start_us += self.dwell_us(self._prev, self._poses[self._index])
            self._prev = self._poses[self._index]
            if self._index + 1 >= len(self._poses):
                self.cycle += 1
                self._cycles_here += 1
                p = self.params
                # a full turn of the base found nothing here: wander instead of turning again
                here = p.turns_per_wander if self.wanders == 0 else p.stop_cycles
                if p.wander_mm > 0 and self._cycles_here >= here and p.cover_mm \
                        and not self.covered:
                    self._cycles_here = 0
                    self._start_leg(now_us, self._prev)
                elif p.wander_mm > 0 and self._cycles_here >= here and not p.cover_mm:
                    self._cycles_here = 0
                    self._start_wander(now_us, self._prev)
                else:
                    self._turning = True
                return self._moving_command(now_us)
            self._index += 1
        return self._command(0)

    def rejoin(self, now_us: int, pose: tuple[int, int, int]) -> None:
        """The caller drove the base off the pattern (to look at a sighting) and is back at
        ``pose``: a ring's leg under way, or the turn before it, aims at its station again from
        there; otherwise the pose in hand is held from ``now_us`` on."""
        self._pose = (int(pose[0]), int(pose[1]), int(pose[2]))
        if self.params.cover_mm and self._stations is not None \
                and (self._wandering or self._corner):
            self._start_leg(now_us, self._wpose)
        else:
            self._pose_start_us = int(now_us)

    def restart_dwell(self, now_us: int) -> None:
        """Hold the current pose from ``now_us`` on (after the caller paused the search)."""
        self._pose_start_us = int(now_us)

    @property
    def turning(self) -> bool:
        """The base is asked to turn (the arm holds, nothing is looked for) or to wander."""
        return self._turning or self._wandering

    @property
    def wandering(self) -> bool:
        return self._wandering

    @property
    def sweep_side(self) -> int:
        """The side the sweep while driving looks to: 0 both, 1 left, -1 right alone."""
        return 0 if self._wsweep is self._wsweeps[0] else 1 if self._wsweep is self._wsweeps[1] \
            else -1

    def _next_cycle(self, now_us: int, at: tuple[int, int] | None = None) -> None:
        th2, th5 = at if at is not None else self._poses[self._index]
        # from the lower half climb first, from the upper half descend first
        self._upward = th2 <= (self.params.theta2_min_mrad + self.params.theta2_max_mrad) // 2
        self._poses = search_cycle(self.params, th2, th5, self._upward,
                                   coarse=self.cycle >= self.params.dense_cycles)
        self._index = 0
        self._prev = (th2, th5)
        self._pose_start_us = int(now_us)
        self._turning = self._wandering = self._corner = False

    def base_turn_done(self, now_us: int) -> None:
        """The base has turned: start a new cycle from the end of the theta2 range we are at,
        or (a corner of the wander spiral) the next leg."""
        if self._turning and self._corner:
            self._start_wander(now_us, self._wpose)
        elif self._turning:
            self._next_cycle(now_us)

    def wander_done(self, now_us: int) -> None:
        """The base has driven its wander: search again from here."""
        self._rounds = 0
        self._end_wander(now_us)

    def wander_blocked(self, now_us: int, can_round: bool = True) -> bool:
        """The base stopped short of the leg's end, an obstacle ahead. True: the caller is to
        drive round it (``can_round``: it has a way) and then call :meth:`wander_resume`; on a
        leg sweeping outward alone, fewer than ``round_tries`` times since a leg last ended
        unblocked. Else (False) the leg ends: the next station."""
        p = self.params
        if self._wandering and p.cover_mm and can_round and self._rounds < p.round_tries \
                and self._outward_side() != 0:
            self._rounds += 1
            return True
        self._end_wander(now_us)
        return False

    def wander_look(self, now_us: int) -> None:
        """The base stopped short of the leg's end with the object possibly in front (the
        caller's evidence): the leg ends, and one cycle at rest looks around here before the
        next station."""
        self._end_wander(now_us, look=True)

    def wander_resume(self, now_us: int) -> None:
        """The caller has driven round the obstacle: aim at the same station from here."""
        if self._wandering:
            at = self._wpose
            self._start_leg(now_us, at)
            if self.covered:
                self._next_cycle(now_us, at)

    @property
    def station_xy(self) -> tuple[int, int] | None:
        """The odometry place of the station the rings' leg drives to; None off the rings."""
        if self._stations is None or self._station >= len(self._stations):
            return None
        return self._stations[self._station]

    @property
    def passing(self) -> bool:
        """A leg after a drive round an obstacle (until one ends unblocked): the caller stops
        it only for something in its way, not for the obstacle it passes beside."""
        return self.params.cover_mm > 0 and self._rounds > 0

    def _end_wander(self, now_us: int, look: bool = False) -> None:
        if self._wandering:
            self.wanders += 1
            p = self.params
            at = self._wpose if p.wander_sweep else (p.coarse_theta2_mrad[0], p.theta5_max_mrad)
            if p.cover_mm:
                self._station += 1  # reached, or stopped short by an obstacle: the next one
                if p.stop_cycles == 0 and not look:
                    self._start_leg(now_us, at)
                    if not self.covered:
                        return
                self._next_cycle(now_us, at)
                return
            if p.stop_cycles == 0:  # a corner of the square spiral: turn, then the next leg
                self._wandering, self._turning, self._corner = False, True, True
                self._wpose = at
                return
            self._next_cycle(now_us, at)
