"""Object search with the eye-in-hand camera, 000 §III.B.2 Fig. 5 and §III.A.

The wrist pitch theta2 oscillates over [theta2_min, theta2_max] = [-2.8, -2.1] rad in steps of
d_theta2 = 0.06 rad (000 §IV); for each theta2 the waist theta5 sweeps from one end of
[theta5_min, theta5_max] = [-0.8, 0.8] rad to the other (boustrophedon: the next sweep goes back),
in steps of d_theta5 (ours: 0.2 rad, under the 0.51 rad horizontal field of view at f = 611 px).
The search starts from the joints at hand (theta2s, theta5s of Fig. 5): the first sweep runs
from theta5s to the far end, theta2 first climbs to theta2_max, then the levels below theta2s
are visited down to theta2_min; every level is swept once per cycle.  When a whole cycle finds
nothing the base turns by a fixed angle (60 degrees here) and a new cycle starts from the other
end of the theta2 range.  theta3, theta4 hold a search posture (parameters) during the search.

Each pose is held for a dwell long enough for the servo travel and ``frames_per_pose`` camera
frames (2 frames at 15 fps = 133 ms by default).  Time is simulated: the caller passes now_us.
"""

from __future__ import annotations

from dataclasses import dataclass

FRAME_PERIOD_US = 66_667  # 15 fps


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
    frames_per_pose: int = 2
    frame_period_us: int = FRAME_PERIOD_US
    servo_speed_mrad_per_s: int = 5000  # hobby servo, about 0.2 s per 60 degrees

    def __post_init__(self) -> None:
        if self.theta2_min_mrad >= self.theta2_max_mrad:
            raise ValueError("theta2_min_mrad must be below theta2_max_mrad")
        if self.theta5_min_mrad >= self.theta5_max_mrad:
            raise ValueError("theta5_min_mrad must be below theta5_max_mrad")
        for name in ("d_theta2_mrad", "d_theta5_mrad", "frames_per_pose", "frame_period_us",
                     "servo_speed_mrad_per_s"):
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
    cycle: int  # completed cycles (= base turns requested)


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


def _sweep(lo: int, hi: int, step: int, frm: int, to_hi: bool) -> list[int]:
    frm = min(max(frm, lo), hi)
    if to_hi:
        return list(range(frm, hi, step)) + [hi]
    return list(range(frm, lo, -step)) + [lo]


def search_cycle(params: SearchParams, theta2_start_mrad: int, theta5_start_mrad: int,
                 upward: bool = True) -> list[tuple[int, int]]:
    """All (theta2, theta5) poses of one search cycle, in order (Fig. 5 of 000)."""
    p = params
    poses: list[tuple[int, int]] = []
    th5 = min(max(theta5_start_mrad, p.theta5_min_mrad), p.theta5_max_mrad)
    # first sweep toward the far end from theta5s
    to_hi = (th5 - p.theta5_min_mrad) <= (p.theta5_max_mrad - th5)
    for th2 in _levels(p.theta2_min_mrad, p.theta2_max_mrad, p.d_theta2_mrad,
                       theta2_start_mrad, upward):
        sweep = _sweep(p.theta5_min_mrad, p.theta5_max_mrad, p.d_theta5_mrad, th5, to_hi)
        poses.extend((th2, t5) for t5 in sweep)
        th5 = sweep[-1]
        to_hi = not to_hi
    return poses


class ArmSearch:
    """The search as a state object over simulated time.

    ``step(now_us)`` returns the current :class:`SearchCommand`; after a cycle it carries a
    ``base_turn_mrad`` request until the caller reports :meth:`base_turn_done`.
    """

    def __init__(self, params: SearchParams, theta2_start_mrad: int, theta5_start_mrad: int,
                 now_us: int) -> None:
        self.params = params
        self.cycle = 0
        self._upward = True
        self._poses = search_cycle(params, theta2_start_mrad, theta5_start_mrad, True)
        self._index = 0
        self._prev = (theta2_start_mrad, theta5_start_mrad)
        self._pose_start_us = int(now_us)
        self._turning = False

    def dwell_us(self, frm: tuple[int, int], to: tuple[int, int]) -> int:
        """Servo travel of the larger joint move plus the frames to look."""
        p = self.params
        travel = max(abs(frm[0] - to[0]), abs(frm[1] - to[1]))
        return travel * 1_000_000 // p.servo_speed_mrad_per_s + p.frames_per_pose * \
            p.frame_period_us

    def _command(self, turn: int) -> SearchCommand:
        th2, th5 = self._poses[self._index]
        p = self.params
        return SearchCommand(th2, p.theta3_mrad, p.theta4_mrad, th5, turn, self._index, self.cycle)

    def step(self, now_us: int) -> SearchCommand:
        """Advance the pattern to ``now_us`` and return the command in force."""
        if self._turning:
            return self._command(self.params.base_turn_mrad)
        while now_us - self._pose_start_us >= self.dwell_us(self._prev, self._poses[self._index]):
            self._pose_start_us += self.dwell_us(self._prev, self._poses[self._index])
            self._prev = self._poses[self._index]
            if self._index + 1 >= len(self._poses):
                self._turning = True
                self.cycle += 1
                return self._command(self.params.base_turn_mrad)
            self._index += 1
        return self._command(0)

    def restart_dwell(self, now_us: int) -> None:
        """Hold the current pose from ``now_us`` on (after the caller paused the search)."""
        self._pose_start_us = int(now_us)

    @property
    def turning(self) -> bool:
        return self._turning

    def base_turn_done(self, now_us: int) -> None:
        """The base has turned: start a new cycle from the end of the theta2 range we are at."""
        if not self._turning:
            return
        th2, th5 = self._poses[self._index]
        # from the lower half climb first, from the upper half descend first
        self._upward = th2 <= (self.params.theta2_min_mrad + self.params.theta2_max_mrad) // 2
        self._poses = search_cycle(self.params, th2, th5, self._upward)
        self._index = 0
        self._prev = (th2, th5)
        self._pose_start_us = int(now_us)
        self._turning = False
