"""The task's parameters: integer mm, mrad, us, the papers' values where they give one.

Each method's module (host/task/method000.py ...) says how its defaults differ
(``param_defaults``); a scenario's ``[task]`` table and its paper parameters, mapped by the
method's ``paper_to_task`` (host/app_factory.py), override them by name (an unknown name is an
error naming it).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

from mobigrasp.host.task.method import method_rules

DEFAULT_TIMEOUTS_US = {
    "SEARCH": 180_000_000, "APPROACH": 120_000_000, "ADJUST": 60_000_000,
    "ROUGH_GRASP": 15_000_000,  # 001's look before the grasp included (grasp.py)
    "PRECISE_GRASP": 30_000_000,
    "LIFT": 16_000_000,  # the lift and the grasp check's look, its roll scan included (grasp.py)
    "LOST": 5_000_000,
}


@dataclass(frozen=True)
class TaskParams:
    """Task parameters (integer mm, mrad, us); papers' values where they give one."""

    timeouts_us: dict = field(default_factory=lambda: dict(DEFAULT_TIMEOUTS_US))
    mount_forward_mm: int = 100  # waist axis ahead of the wheel axle (mcu_sim/world/arm.py)
    h_shoulder_mm: int = 200  # 000; 001: 108; 002: 50 (mcu_sim/world/arm.py ARM_BY_METHOD)
    object_top_mm: int = 100  # object top above the ground (000 card; 002 cylinder 120)
    grasp_height_mm: int = 80  # grasp point above the ground
    hover_mm: int = 110  # rough grasp: camera this far above the object top (000)
    lift_mm: int = 60
    approach_standoff_mm: int = 400  # 000 P3: axle this far from the object
    grasp_r_mm: int = 110  # object this far ahead of the waist axis for the grasp
    grasp_r_tol_mm: int = 20
    bearing_tol_mrad: int = 60
    adjust_vmax_mmps: int = 80
    adjust_theta3_mrad: int = -1000  # ADJUST close-look posture (host/task/adjust.py)
    adjust_theta4_mrad: int = 1571
    blind_finish_mm: int = 80  # ADJUST may finish on odometry within this of its goal
    lost_timeout_us: int = 1_500_000
    blind_approach_mm: int = 1000  # 002: drive on toward the marker's last bearing this far
    blind_approach_us: int = 8_000_000  # ... and at most this long (1 m at 0.15 m/s: 6.7 s)
    blind_keep_mm: int = 700  # ... but stop it this short of the board's distance (crosses)
    lost_hold_us: int = 500_000
    max_lost: int = 5
    turn_wheel_mmps: int = 80
    search_turn_wheel_mmps: int = 0  # SEARCH's base turns (look-around, ring corners); 0: the above
    wander_mmps: int = 200  # SEARCH wander speed (host.search); the planners' v_max is 250
    wander_clear_mm: int = 500  # a wander stops when a front sonar sees something this close
    sighting_match_mm: int = 200  # SEARCH: an unconfirmed sighting seen again this close is it
    # SEARCH: an unconfirmed sighting farther than sighting_approach_mm + sighting_match_mm from
    # the axle is driven to until sighting_approach_mm away, then looked at (search.py
    # ``far_sighting``); 0: dropped. At most sighting_approaches a run
    sighting_approach_mm: int = 0
    sighting_approaches: int = 2
    replan_period_us: int = 300_000  # 001: sonar check of the rest of the path (replan.py)
    sonar_sweep_us: int = 200_000  # 001: first plan after one sweep of the 5 sonars (5 x 30 ms)
    sonar_offset_mm: int = 170  # the sonars on the 0.17 m footprint circle (mcu_sim/world/sonar)
    w_min_px: int = 20  # 000 §IV: the precise grasp's window for w_T (host.kinematics)
    w_max_px: int = 40
    r_r_mm: int = 200  # safety circle R_r (001 eq. (16)); a front sonar range below it stops
    sonar_a_g_mrad: int = 1050  # cone width A_g of each sonar (001 §IV)
    sonar_d_e_mm: int = 2500  # 001: sonar range D_e, "nothing detected" (§IV)
    # 001: two neighbours' echoes this close are one echo in their overlap; their mounts on the
    # 0.17 m circle are 2 x 0.17 sin(pi/8) = 130 mm apart, so one point's ranges differ that much
    sonar_shared_echo_mm: int = 130
    replan_shift_mm: int = 150  # 000: replan when the object estimate moved this far
    max_plan_attempts: int = 3
    direct_max_mm: int = 1200  # no feasible curve after all attempts: ADJUST if this close
    max_detours: int = 6  # 001: drive aside (host/task/method001.py) this often before giving up
    detour_mm: int = 500  # length of one drive aside
    detour_clear_mm: int = 900  # a sonar reading at least this is a free direction
    servo_speed_mrad_per_s: int = 3000  # for settle times
    settle_margin_us: int = 300_000
    posture_step_mrad: int = 20  # per control step (1 rad/s at 50 Hz: the servos follow)
    frame_latency_us: int = 50_000  # a detection shows the scene this long ago (capture+vision)
    confirm_us: int = 700_000  # SEARCH: hold the pose this long to see the object again
    spoke_wait_us: int = 3_000_000  # no spoke for this long: grasp on the rough position
    precise_max_steps: int = 30
    precise_align_ch: int = 1  # joint that drives k_T to 0: 1 wrist roll, 5 waist (grasp.py)
    pregrasp_back_mm: int = 50  # 002: pre-grasp point this far short of the object
    grasp_close_timeout_us: int = 2_000_000
    cylinder_near_px: int = 12  # 002: ring spacing at which ADJUST (slow, straight) starts
    cross_near_px: int = 75  # 002: crosses this far apart (board ~0.6 m) place the cylinder
    slow_mmps: int = 60  # 002 ADJUST speed
    t_d_px: int = 45  # 002 T_d
    object_xy_mm: tuple = ()  # 001: P_i given in the odometry frame (skips SEARCH); () unknown
    search: dict = field(default_factory=dict)  # host.search.SearchParams fields
    posture: dict = field(default_factory=dict)  # host.posture.PostureParams fields
    planner: dict = field(default_factory=dict)  # Params000 / Params001 fields
    fuzzy: dict = field(default_factory=dict)  # host.control.fuzzy.FuzzyParams fields

    @classmethod
    def for_method(cls, method: str, overrides: dict | None = None) -> TaskParams:
        """Defaults for a method (its module's ``param_defaults``), then ``overrides`` (unknown
        key -> ValueError naming it)."""
        base = replace(cls(), **method_rules(method).param_defaults)
        overrides = dict(overrides or {})
        known = {f.name: f for f in fields(cls)}
        for key, value in list(overrides.items()):
            if key not in known:
                raise ValueError(f"unknown task parameter {key!r}; known: {sorted(known)}")
            default = getattr(base, key)
            if isinstance(default, dict):
                if not isinstance(value, dict):
                    raise ValueError(f"task parameter {key!r} must be a table, got {value!r}")
                if key == "timeouts_us":
                    bad = [s for s in value if s not in DEFAULT_TIMEOUTS_US]
                    if bad:
                        raise ValueError(f"timeouts_us: unknown state(s) {bad}")
                if key in ("timeouts_us", "search"):  # on top of the method's defaults
                    overrides[key] = {**default, **value}
            elif key == "object_xy_mm":
                if len(value) not in (0, 2) or not all(
                        isinstance(v, int) and not isinstance(v, bool) for v in value):
                    raise ValueError(f"object_xy_mm must be two ints (mm) or empty, got {value!r}")
                overrides[key] = tuple(value)
            elif not isinstance(value, int) or isinstance(value, bool):
                raise ValueError(f"task parameter {key!r} must be an int, got {value!r}")
        return replace(base, **overrides) if overrides else base
