"""Build the host program from its configuration: the task of the method, the detectors, inputs.

The configuration is what the board would be flashed with (method ``"000"``/``"001"``/``"002"``,
the paper parameters, the camera calibration); nothing in it is ground truth. Used by
``mobigrasp host`` (both modes) and by the in-process run.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mobigrasp.host import arm_calib
from mobigrasp.host.app import HostApp, HostConfig
from mobigrasp.host.odometry import Odometry
from mobigrasp.host.posture import PostureParams
from mobigrasp.host.task.method import K_THETA, method_rules
from mobigrasp.host.vision import registry
from mobigrasp.host.vision.frame_key import frame_bytes
from mobigrasp.protocol import messages as m


class InputBuilder:
    """Telemetry + detections → the task's inputs (host.task.TaskInputs), integer units.

    Odometry integrates the encoder counts of every new telemetry frame (host/odometry.py); the
    joint angles come from the measured servo pulse widths through the joint table
    (host/arm_calib.py); a sonar without echo (0xFFFF) is passed on as is.
    """

    # The telemetry flag says the gripper was *commanded* closed; the hobby servo needs about
    # 0.33 s for its 1000 us swing (60 deg / 0.17 s), so "closed" is reported once the flag has
    # been up that long (with margin): lifting earlier would pull the fingers off the object.
    GRIPPER_CLOSE_US = 450_000

    def __init__(self) -> None:
        from mobigrasp.host.task import TaskInputs

        self._inputs = TaskInputs.every_field  # imported here, not in every call (each tick)
        self.odometry = Odometry()
        self._closed_since_us: int | None = None
        self._tel_seen: Any = None
        self._resets_seen = 0
        self.pose = self.odometry.pose

    def joints_mrad(self, tel: m.Telemetry | None) -> tuple[int, ...] | None:
        """Joint angles (ch 0 = gripper per mille) from the telemetry's pulse widths."""
        if tel is None:
            return None
        return arm_calib.pulses_to_joints_mrad(tel.servo_us)

    def __call__(self, app: HostApp, now_us: int, detections: dict) -> Any:
        tel = app.link.telemetry
        if app.link.mcu_resets != self._resets_seen:  # counters and clock restarted at 0
            self._resets_seen = app.link.mcu_resets
            self.odometry.resync()
        if tel is not None and tel is not self._tel_seen:
            self._tel_seen = tel
            self.pose = self.odometry.update(tel.time_us, tel.enc_left, tel.enc_right)
        p = self.pose
        flag = bool(tel is not None and tel.flags & m.FLAG_GRIPPER_CLOSED)
        if not flag:
            self._closed_since_us = None
        elif self._closed_since_us is None:
            self._closed_since_us = now_us
        closed = flag and now_us - self._closed_since_us >= self.GRIPPER_CLOSE_US
        return self._inputs(
            joints_mrad=self.joints_mrad(tel),
            x_mm=p.x_mm, y_mm=p.y_mm, heading_mrad=p.heading_mrad, v_mmps=p.speed_mm_s,
            sonar_mm=tuple(tel.sonar_mm) if tel is not None else (),
            detections=detections,
            grasp_closed=closed,
        )


class _PoseDetector:
    """A detector that needs the arm pose (joint angles from the newest telemetry, as the board
    would read them). HostApp takes :meth:`snapshot` when the frame's job is created and passes
    it back when the detector runs, so the result does not depend on when that is."""

    def __init__(self, run: Any, joints: Any) -> None:
        self._run = run  # (rgb, joints) -> (result | None, OpCounts)
        self._joints = joints

    def snapshot(self) -> tuple:
        """The arguments after ``rgb``: the joint angles now."""
        return (self._joints(),)

    def __call__(self, rgb: Any, q: tuple[int, ...] | None = None) -> Any:
        return self._run(rgb, self._joints() if q is None else q)


class _LastFrameMemo:
    """A detector that answers a repeated call from memory: the result and the operation
    counts of its last call, when the frame's pixels (shape, dtype, bytes) and the other
    arguments are those of that call.

    The camera sends the same image again while the scene stands still (the same render), and
    in ADJUST and LIFT a frame goes to two detectors in turn, so a third to a half of the calls
    of a run repeat the detector's previous call. A detector is a pure function of its
    arguments (integer code, module constants only), so the remembered answer is what it would
    compute (host speed only: the counts, i.e. the modelled ARM9 time, are charged again).
    One entry per detector: the two detectors of a frame each keep their own."""

    def __init__(self, run: Any) -> None:
        self._run = run  # (rgb, *args) -> (result | None, OpCounts)
        self._last: tuple | None = None  # (key, result, OpCounts)

    def __call__(self, rgb: Any, *args: Any) -> Any:
        if not isinstance(rgb, np.ndarray):  # the detector says what is wrong
            return self._run(rgb, *args)
        key = (rgb.shape, rgb.dtype.str, frame_bytes(rgb), args)
        last = self._last
        if last is not None and last[0] == key:
            return last[1], last[2].scaled(1)  # a copy: the caller may add to its counts
        result, ops = self._run(rgb, *args)
        self._last = (key, result, ops.scaled(1))
        return result, ops


def vision_bounds(names) -> dict:
    """``name -> bound(height, width) -> µs``, the lower bound of each detector's modelled time
    (its ``min_ops``, host/vision/registry.py) for HostApp, for the detectors among ``names``."""
    return {name: _time_us_by_size(registry.row(name).min_ops_fn()) for name in names}


def front_ends(names) -> dict:
    """``name -> (front end, its µs(height, width))`` for HostApp, for the detectors among
    ``names`` that start from a shared front end (its ``front_end``, host/vision/registry.py)."""
    out: dict = {}
    for name in names:
        ref, fn = registry.row(name).front_end, registry.row(name).front_end_fn()
        if fn is not None:
            out[name] = (ref, _time_us_by_size(fn))
    return out


def _time_us_by_size(ops_fn):
    """``(height, width) -> µs`` of ``ops_fn(height, width)``'s counts, kept per size (every
    frame of a run has the same)."""
    cache: dict = {}

    def time_us(h: int, w: int) -> int:
        us = cache.get((h, w))
        if us is None:
            us = cache[(h, w)] = ops_fn(h, w).time_us()
        return us
    return time_us


def _detectors(cfg: dict, app_ref: list) -> dict:
    """Detector callables ``rgb -> (result | None, OpCounts)``, one per row of the detector
    table (host/vision/registry.py).

    Some detectors need the current arm pose (e.g. the double cross needs the camera yaw and
    pitch): they read it from the host's newest telemetry, which is what the board would do,
    taken when the frame arrives (:class:`_PoseDetector`).
    """
    cam = cfg.get("camera", {})
    intrinsics = (int(round(cam.get("f_px", 611.0))), int(round(cam.get("u0_px", 160.0))),
                  int(round(cam.get("v0_px", 120.0))))

    def joints() -> tuple[int, ...]:
        tel = app_ref[0].link.telemetry if app_ref else None
        if tel is None:
            return (0, 0, -1571, 0, 0, 0)
        return arm_calib.pulses_to_joints_mrad(tel.servo_us)

    found: dict = {}
    for name, row in registry.DETECTORS.items():
        if row.call == "pose":
            found[name] = _PoseDetector(_LastFrameMemo(
                lambda rgb, q, row=row: row.host_call(rgb, intrinsics, q)), joints)
        else:
            found[name] = _LastFrameMemo(lambda rgb, row=row: row.host_call(rgb, intrinsics, None))
    return found


def task_params(method: str, paper: dict) -> dict:
    """TaskParams overrides from the scenario's paper parameters (only the names the method
    maps, its ``paper_to_task``)."""
    table = method_rules(method).paper_to_task
    out: dict = {}
    for name, value in paper.items():
        if name in table:
            group, key, conv = table[name]
            if group == K_THETA:
                continue  # below
            if group is None:  # a TaskParams field of its own
                out[key] = conv(value)
            else:
                out.setdefault(group, {})[key] = conv(value)
    gains = list(PostureParams().k_theta_q12)
    for name, value in paper.items():
        if name in table and table[name][0] == K_THETA:
            gains[table[name][1]] = table[name][2](value)
            out.setdefault("posture", {})["k_theta_q12"] = tuple(gains)
    if "t_d_px" in out.get("fuzzy", {}):
        out["t_d_px"] = out["fuzzy"]["t_d_px"]
    return out


def build_host_app(cfg: dict, config: HostConfig | None = None, timer=None,
                   recorder=None) -> HostApp:
    """The host program for ``cfg`` = {"method", "params" (paper names), "camera", "task"
    (TaskParams overrides, e.g. ``object_xy_mm`` for 001)}; method ``"idle"``: the program
    around no task (host/task/idle.py). ``timer`` and ``recorder``: HostApp's hooks."""
    from mobigrasp.host.task import Task
    from mobigrasp.host.task.idle import PROGRAM_TASKS

    method = cfg.get("method", "000")
    task: Any
    if method in PROGRAM_TASKS:  # the host program's own task (idle), no paper's
        task = PROGRAM_TASKS[method]()
    else:
        params = task_params(method, dict(cfg.get("params", {})))
        for key, value in dict(cfg.get("task", {})).items():  # task settings, e.g. 001's P_i
            params[key] = tuple(value) if isinstance(value, list) else value
        task = Task(method=method, params=params)
    app_ref: list = []
    detectors = _detectors(cfg, app_ref)
    app = HostApp(task, detectors, InputBuilder(), config or HostConfig(), timer=timer,
                  vision_bounds=vision_bounds(detectors), front_ends=front_ends(detectors),
                  recorder=recorder)
    app_ref.append(app)
    return app
