"""trace.mcap of a run folder: the trace (and the camera frames) for Foxglove, no conversion.

Written as the run goes (:class:`McapLog`): at every camera frame the frame (JPEG) and the
trace lines written since the last one (read back from trace.jsonl, flushed per line) go into
the file, a chunk per simulated second, so nothing is held until the end and a run killed
outright leaves a file readable up to its last second (:func:`read_messages`); the summary's
totals and the index are added when the run ends. Every message's log
time and publish time are its *simulated* time (ns), so Foxglove's timeline is the run's clock.
JSON encoding with the Foxglove schemas by name (services/mcap_schemas.py); docs/outputs.md lists
the topics.

The arm's frames follow eq. (3) of 000 (mcu_sim/world/arm.py): the waist ``mount_forward_m``
ahead of the axle at the shoulder height, turned by -theta5 (theta5 turns to the right); then
pitch joints theta4 (shoulder), theta3 (elbow), theta2 (wrist), each link along its x axis
(l1, l2, l3), the roll theta1 about l3 and the camera (OpenCV axes, z along l3) at its end.
"""

from __future__ import annotations

import base64
import json
import math
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import cv2
import numpy as np

from mobigrasp.cosim.run_folder import detection_points
from mobigrasp.services.mcap_schemas import SCHEMAS
from mobigrasp.services.plan_paths import odom_to_world, plan_paths_world

TOPICS: dict[str, str] = {
    "/camera/image": "foxglove.CompressedImage",
    "/camera/calibration": "foxglove.CameraCalibration",
    "/camera/detections": "foxglove.ImageAnnotations",
    "/tf": "foxglove.FrameTransform",
    "/scene": "foxglove.SceneUpdate",
    "/task/state": "foxglove.Log",
    "/joints": "mobigrasp.Joints",
    "/wheels/commanded": "mobigrasp.Wheels",
    "/wheels/measured": "mobigrasp.Wheels",
    "/fuzzy": "mobigrasp.Fuzzy",
    "/arm9/load": "mobigrasp.Load",
    "/protocol/counters": "mobigrasp.ProtocolCounters",
    # a host program's serial line decoded (``sim``: trace "wire" events)
    "/wire/to_mcu": "mobigrasp.WireMessage",
    "/wire/to_host": "mobigrasp.WireMessage",
    "/wire/nacks": "mobigrasp.Nack",
    "/wire/watchdog": "mobigrasp.WatchdogTrip",
    "/mcu/encoders": "mobigrasp.Encoders",
    "/mcu/sonars": "mobigrasp.Sonars",
}
# the arm's frames, base to camera (a /tf message each per truth sample with joint angles)
ARM_FRAMES = ("waist", "upper_arm", "forearm", "wrist", "gripper", "camera")
# trace events that move a protocol counter: event -> counter
PROTOCOL_EVENTS = {"nack": "nacks", "reliable_failed": "reliable_failed",
                   "output_rejected": "output_rejected", "mcu_reset_seen": "mcu_resets_seen",
                   "deadline_miss": "deadline_misses", "frame_dropped": "frames_dropped"}
JPEG_QUALITY = 85
GREEN = {"r": 0.1, "g": 0.9, "b": 0.1, "a": 1.0}
RED = {"r": 0.9, "g": 0.1, "b": 0.1, "a": 1.0}
GREY = {"r": 0.5, "g": 0.5, "b": 0.5, "a": 0.8}
BLUE = {"r": 0.1, "g": 0.3, "b": 0.9, "a": 1.0}
FAINT_RED = {"r": 0.9, "g": 0.2, "b": 0.2, "a": 0.35}
CLEAR = {"r": 0.0, "g": 0.0, "b": 0.0, "a": 0.0}
TARGET_SIZE_M = 0.06


def _jpeg(rgb: np.ndarray) -> bytes:
    ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2BGR),
                            [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    if not ok:
        raise ValueError("JPEG encoding of a camera frame failed")
    return jpeg.tobytes()


def stamp(t_us: int) -> dict:
    """Foxglove time of a simulated time in µs."""
    return {"sec": int(t_us) // 1_000_000, "nsec": (int(t_us) % 1_000_000) * 1000}


def _quat_axis(axis: str, angle: float) -> dict:
    s, c = math.sin(angle / 2), math.cos(angle / 2)
    q = {"x": 0.0, "y": 0.0, "z": 0.0, "w": c}
    q[axis] = s
    return q


def _quat_matrix(m: list[list[float]]) -> dict:
    """Quaternion of a proper rotation matrix (rows)."""
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        return {"x": (m[2][1] - m[1][2]) / s, "y": (m[0][2] - m[2][0]) / s,
                "z": (m[1][0] - m[0][1]) / s, "w": s / 4}
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0, 0.0, 0.0]
    q[i] = s / 4
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    return {"x": q[0], "y": q[1], "z": q[2], "w": (m[k][j] - m[j][k]) / s}


# camera axes in the gripper frame (x along l3, y left, z up): x_c = -y, y_c = -z, z_c = x
CAMERA_IN_GRIPPER = _quat_matrix([[0, 0, 1], [-1, 0, 0], [0, -1, 0]])


def _tf(t_us: int, parent: str, child: str, xyz=(0.0, 0.0, 0.0), rotation=None) -> dict:
    return {"timestamp": stamp(t_us), "parent_frame_id": parent, "child_frame_id": child,
            "translation": {"x": float(xyz[0]), "y": float(xyz[1]), "z": float(xyz[2])},
            "rotation": rotation or {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}


def arm_transforms(t_us: int, joints_rad: list[float], geom) -> list[dict]:
    """base -> waist -> upper_arm -> forearm -> wrist -> gripper -> camera (ARM_FRAMES)."""
    t1, t2, t3, t4, t5 = (float(joints_rad[k]) for k in range(1, 6))
    # a pitch up by a is a rotation of -a about y (x forward, z up)
    return [
        _tf(t_us, "base", "waist", (geom.mount_forward_m, 0.0, geom.h_shoulder_m),
            _quat_axis("z", -t5)),
        _tf(t_us, "waist", "upper_arm", rotation=_quat_axis("y", -t4)),
        _tf(t_us, "upper_arm", "forearm", (geom.l1, 0.0, 0.0), _quat_axis("y", -t3)),
        _tf(t_us, "forearm", "wrist", (geom.l2, 0.0, 0.0), _quat_axis("y", -t2)),
        _tf(t_us, "wrist", "gripper", (geom.l3, 0.0, 0.0), _quat_axis("x", t1)),
        _tf(t_us, "gripper", "camera", rotation=CAMERA_IN_GRIPPER),
    ]


def _pose(x: float, y: float, z: float, yaw: float = 0.0) -> dict:
    return {"position": {"x": x, "y": y, "z": z}, "orientation": _quat_axis("z", yaw)}


def _entity(t_us: int, frame: str, ident: str, **prims) -> dict:
    entity = {"timestamp": stamp(t_us), "frame_id": frame, "id": ident,
              "lifetime": stamp(0), "frame_locked": frame != "world", "metadata": [],
              "arrows": [], "cubes": [], "spheres": [], "cylinders": [], "lines": [],
              "triangles": [], "texts": [], "models": []}
    entity.update(prims)
    return entity


def _line(points: list, color: dict, thickness: float) -> dict:
    return {"type": 0, "pose": _pose(0.0, 0.0, 0.0), "thickness": thickness,
            "scale_invariant": True, "points": [{"x": p[0], "y": p[1], "z": 0.01}
                                                for p in points],
            "color": color, "colors": [], "indices": []}


def obstacle_entity(start: dict) -> dict:
    """The scenario's obstacles (circle: cylinder, box: cube, wall: line) as one entity."""
    cubes, cylinders, lines = [], [], []
    for o in start.get("obstacles", []):
        h = float(o.get("height_m") or 0.3)
        if o.get("shape") == "circle":
            d = 2 * o["radius_m"]
            cylinders.append({"pose": _pose(o["x_m"], o["y_m"], h / 2), "size":
                              {"x": d, "y": d, "z": h}, "bottom_scale": 1.0, "top_scale": 1.0,
                              "color": GREY})
        elif o.get("shape") == "box":
            cubes.append({"pose": _pose(o["x_m"], o["y_m"], h / 2, o.get("heading_rad") or 0.0),
                          "size": {"x": o["width_m"], "y": o["depth_m"], "z": h},
                          "color": GREY})
        elif o.get("shape") == "wall":
            lines.append(_line([(o["x_m"], o["y_m"]), (o["x2_m"], o["y2_m"])], GREY, 4.0))
    return _entity(0, "world", "obstacles", cubes=cubes, cylinders=cylinders, lines=lines)


def target_entity(name: str) -> dict:
    """The object, drawn in its own frame (world -> target follows it on /tf)."""
    s = TARGET_SIZE_M
    return _entity(0, "target", "target", spheres=[{
        "pose": _pose(0.0, 0.0, s / 2), "size": {"x": s, "y": s, "z": s}, "color": RED}],
        texts=[{"pose": _pose(0.0, 0.0, 2 * s), "billboard": True, "font_size": 12.0,
                "scale_invariant": True, "color": RED, "text": name}])


def plan_entity(t_us: int, plan: dict, to_world) -> dict:
    """Candidates (faint red) and the chosen path (blue) of one plan, in the world frame."""
    cands, best = plan_paths_world(plan, to_world)
    lines = [_line(path, FAINT_RED, 1.0) for path in cands]
    lines += [_line(path, BLUE, 3.0) for path in best]
    return _entity(t_us, "world", "plan", lines=lines)


def detection_annotations(event: dict) -> dict:
    """A circle at every detected point (Q4 px -> px) and a line per detector (name and
    found/none); stamped with the frame's capture time so Foxglove pairs it with the image."""
    ts = stamp(event.get("capture_us", event["t_us"]))
    circles, texts = [], []
    for k, (name, result) in enumerate(sorted((event.get("results") or {}).items())):
        found = result is not None
        for u, v in detection_points(result):
            circles.append({"timestamp": ts, "position": {"x": float(u), "y": float(v)},
                            "diameter": 10.0, "thickness": 2.0, "fill_color": CLEAR,
                            "outline_color": GREEN})
        texts.append({"timestamp": ts, "position": {"x": 4.0, "y": 14.0 + 12.0 * k},
                      "text": f"{name}: {'found' if found else 'none'}", "font_size": 11.0,
                      "text_color": GREEN if found else RED, "background_color": CLEAR})
    return {"circles": circles, "points": [], "texts": texts}


def _state_log(event: dict) -> dict:
    if event["ev"] == "end":
        msg, level = f"run ended in {event.get('host_state')}: {event.get('reason')}", 2
    else:
        to = event.get("to", "")
        msg = f"{event.get('from', '')} -> {to}: {event.get('why', '')}"
        level = 3 if to == "FAILED" else 2
    return {"timestamp": stamp(event["t_us"]), "level": level, "message": msg,
            "name": "task", "file": "", "line": 0}


def measured_wheels(prev: dict, cur: dict, track_m: float) -> dict | None:
    """Wheel speeds of the simulated base between two truth samples (mm/s)."""
    dt = (cur["t_us"] - prev["t_us"]) / 1e6
    if dt <= 0:
        return None
    dx, dy = cur["x_m"] - prev["x_m"], cur["y_m"] - prev["y_m"]
    h = prev.get("heading_rad") or 0.0
    v = (dx * math.cos(h) + dy * math.sin(h)) / dt
    dh = math.remainder((cur.get("heading_rad") or 0.0) - h, math.tau)
    w = dh / dt
    return {"left_mmps": round(1000 * (v - w * track_m / 2), 1),
            "right_mmps": round(1000 * (v + w * track_m / 2), 1)}


def wire_messages(e: dict, state: dict) -> list[tuple[str, dict]]:
    """(topic, message) of one trace "wire" event: every frame on /wire/to_mcu or
    /wire/to_host, a NACK also on /wire/nacks (its reason by name, the count so far), a rise of
    Telemetry's watchdog counter on /wire/watchdog, a SET_WHEELS on /wheels/commanded;
    ``state`` carries the counts between events."""
    from mobigrasp.mcu_sim.wire_names import nack_reason_name

    t, name = int(e["t_us"]), e.get("msg")
    msg = {"timestamp": stamp(t), "seq": e["seq"], "msg": name or f"type_{e.get('msg_type')}",
           "fields": e.get("fields", {})}
    if "error" in e:
        msg["error"] = e["error"]
    out = [("/wire/" + e["dir"], msg)]
    fields = e.get("fields", {})
    if e["dir"] == "to_mcu" and name == "SetWheels":
        out.append(("/wheels/commanded", {"left_mmps": fields["left_mmps"],
                                          "right_mmps": fields["right_mmps"]}))
    elif name == "Nack":
        state["nacks"] = state.get("nacks", 0) + 1
        out.append(("/wire/nacks", {"timestamp": stamp(t), "acked_seq": fields["acked_seq"],
                                    "reason": nack_reason_name(fields["reason"]),
                                    "count": state["nacks"]}))
    elif name == "Telemetry":
        if "enc_left" in fields and "enc_right" in fields:
            out.append(("/mcu/encoders", {"timestamp": stamp(t), "enc_left": fields["enc_left"],
                                          "enc_right": fields["enc_right"]}))
        if "sonar_mm" in fields:
            out.append(("/mcu/sonars", {"timestamp": stamp(t),
                                        "sonar_mm": list(fields["sonar_mm"])}))
        trips = fields["watchdog_trips"]
        if trips > state.get("trips", 0):
            out.append(("/wire/watchdog", {"timestamp": stamp(t), "trips": trips}))
        state["trips"] = trips
    return out


ROBOT_COLOR = {"r": 0.95, "g": 0.6, "b": 0.1, "a": 0.9}
LINK_THICKNESS_M = 0.025


def robot_entities(geom, footprint_radius_m: float) -> list[dict]:
    """The robot in the 3D panel: the base's footprint (frame "base") and each arm link as a box
    along its frame's x axis (upper_arm l1, forearm l2, wrist l3), frame-locked, so /tf moves
    them with the joints (eq. (3) of 000)."""
    d = 2 * footprint_radius_m
    base = _entity(0, "base", "robot/base", cylinders=[{
        "pose": _pose(0.0, 0.0, 0.05), "size": {"x": d, "y": d, "z": 0.1},
        "bottom_scale": 1.0, "top_scale": 1.0, "color": ROBOT_COLOR}])
    links = []
    for frame, length in (("upper_arm", geom.l1), ("forearm", geom.l2), ("wrist", geom.l3)):
        links.append(_entity(0, frame, f"robot/{frame}", cubes=[{
            "pose": _pose(length / 2, 0.0, 0.0),
            "size": {"x": length, "y": LINK_THICKNESS_M, "z": LINK_THICKNESS_M},
            "color": ROBOT_COLOR}]))
    return [base, *links]


def camera_calibration(camera: dict) -> dict:
    """foxglove.CameraCalibration of the pinhole camera (f, u0, v0 in px; no distortion), so
    the 3D panel can project the image and the image panel draw the scene."""
    f, u0, v0 = float(camera["f_px"]), float(camera["u0_px"]), float(camera["v0_px"])
    return {"timestamp": stamp(0), "frame_id": "camera", "width": int(camera["width"]),
            "height": int(camera["height"]), "distortion_model": "plumb_bob",
            "D": [0.0] * 5, "K": [f, 0.0, u0, 0.0, f, v0, 0.0, 0.0, 1.0],
            "R": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            "P": [f, 0.0, u0, 0.0, 0.0, f, v0, 0.0, 0.0, 0.0, 1.0, 0.0]}


class _Topics:
    """Trace events -> MCAP messages, one event at a time (the state the conversion carries:
    the start event, the last truth sample and the protocol counters)."""

    def __init__(self, start: dict, camera: dict | None = None) -> None:
        from mobigrasp.host.task import METHODS, method_rules
        from mobigrasp.mcu_sim.world.arm import ARM_BY_METHOD

        self.start = start
        method = str(start.get("method"))
        # the robot the world built for the run's method (a trace of no known method: 000's)
        self.geom = ARM_BY_METHOD[method_rules(method).robot if method in METHODS else "000"]
        self.to_world = odom_to_world(start)
        self.counters = dict.fromkeys(PROTOCOL_EVENTS.values(), 0)
        self.prev_truth: dict | None = None
        self.wire_state: dict = {}
        self.camera = camera

    def first(self) -> list[tuple[int, str, dict]]:
        """The scene (robot, obstacles, target), the camera's calibration and the counters at
        time 0."""
        from mobigrasp.mcu_sim.world.base import FOOTPRINT_RADIUS_M

        out = [(0, "/scene", {"deletions": [], "entities": [
                    *robot_entities(self.geom, FOOTPRINT_RADIUS_M), obstacle_entity(self.start),
                    target_entity(str(self.start.get("scenario", "target")))]}),
               (0, "/protocol/counters", dict(self.counters))]
        if self.camera is not None:
            out.append((0, "/camera/calibration", camera_calibration(self.camera)))
        return out

    def event(self, e: dict) -> list[tuple[int, str, dict]]:
        """The messages of one trace event."""
        from mobigrasp.mcu_sim.world.base import WHEEL_TRACK_M

        out: list[tuple[int, str, dict]] = []
        t, ev = int(e["t_us"]), e["ev"]
        if ev == "truth" and e.get("x_m") is not None:
            out.append((t, "/tf", _tf(t, "world", "base", (e["x_m"], e["y_m"], 0.0),
                                      _quat_axis("z", e.get("heading_rad") or 0.0))))
            if e.get("obj"):
                out.append((t, "/tf", _tf(t, "world", "target", e["obj"])))
            if e.get("joints_rad"):
                out.extend((t, "/tf", tf) for tf in arm_transforms(t, e["joints_rad"], self.geom))
                j = e["joints_rad"]
                out.append((t, "/joints", {"joints_rad": list(j), "gripper": j[0],
                                           "roll_rad": j[1], "wrist_rad": j[2],
                                           "elbow_rad": j[3], "shoulder_rad": j[4],
                                           "waist_rad": j[5]}))
            if self.prev_truth is not None:
                measured = measured_wheels(self.prev_truth, e, WHEEL_TRACK_M)
                if measured is not None:
                    out.append((t, "/wheels/measured", measured))
            self.prev_truth = e
        elif ev == "detect":
            out.append((t, "/camera/detections", detection_annotations(e)))
        elif ev in ("state", "end"):
            out.append((t, "/task/state", _state_log(e)))
        elif ev == "wheels":
            left, right = e["mmps"]
            out.append((t, "/wheels/commanded", {"left_mmps": left, "right_mmps": right}))
        elif ev == "wire":
            out.extend((t, topic, msg) for topic, msg in wire_messages(e, self.wire_state))
        elif ev == "load":
            out.append((t, "/arm9/load", {"load": e["load"], "window_us": e.get("window_us")}))
        elif ev == "detail" and isinstance(e.get("plan"), dict):
            out.append((t, "/scene", {"deletions": [], "entities": [
                plan_entity(t, e["plan"], self.to_world)]}))
        elif ev == "detail" and isinstance(e.get("fuzzy"), dict):
            f = e["fuzzy"]
            out.append((t, "/fuzzy", {"e_mrad": f.get("e_mrad"), "e_c_mrad_s": f.get(
                "e_c_mrad_s"), "u_mrad": f.get("u_mrad")}))
        if ev in PROTOCOL_EVENTS:
            self.counters[PROTOCOL_EVENTS[ev]] += 1
            out.append((t, "/protocol/counters", dict(self.counters)))
        return out

    def end(self, summary: dict) -> tuple[int, str, dict]:
        """The run's totals, at its end."""
        end_us = int(round(1e6 * (summary.get("sim_time_s") or 0.0)))
        proto = summary.get("protocol") or {}
        return (end_us, "/protocol/counters", {**self.counters, **{
            k: proto.get(k) for k in ("tx_frames", "rx_frames", "crc_errors", "retransmits")}})


def image_message(capture_us: int, jpeg: bytes) -> dict:
    """A camera frame as a foxglove.CompressedImage."""
    return {"timestamp": stamp(capture_us), "frame_id": "camera", "format": "jpeg",
            "data": base64.b64encode(jpeg).decode("ascii")}


# A chunk is closed at every simulated second or at CHUNK_BYTES, whichever comes first, and
# the run goes on past a second only once that second's chunk is in the file: a kill loses at
# most the last second. The writer keeps one index entry (~1 kB) per chunk until the end: a
# second's chunk keeps that small (docs/outputs.md "Trace size" for the figures).
CHUNK_PERIOD_US = 1_000_000
CHUNK_BYTES = 4 * 1024 * 1024
_MAX_PENDING_FRAMES = 8  # frames queued for the encoder before on_frame waits for one
# the MCU's bytes to the host gathered before they go to the writer with the next frame, or on
# their own past this many (a run whose camera is off has no frames)
_MCU_BATCH_BYTES = 16 * 1024


TELEMETRY_TOPICS = ("/mcu/encoders", "/mcu/sonars")


def telemetry_messages(t_us: int, frame) -> list[tuple[int, str, dict]]:
    """The encoder and sonar messages of one frame the MCU sent, exactly as ``sim``'s wire
    event of it gives them (:func:`wire_messages`); none for another message or an
    undecodable one."""
    from mobigrasp.cosim.serve.external_host import wire_event

    event = wire_event("to_host", t_us, frame)
    if event.get("msg") != "Telemetry":
        return []
    return [(t_us, topic, msg) for topic, msg in wire_messages(event, {})
            if topic in TELEMETRY_TOPICS]


class McapLog:
    """trace.mcap written as the run goes; the rig's ``on_frame`` hook.

    Frames are JPEG-encoded (a 320x240 frame is ~10 kB) and written by one worker thread (cv2
    releases the GIL: the run's loop does not wait for the encoder), which also converts the
    trace lines of ``trace`` (default: trace.jsonl beside ``path``) written since the frame
    before. At most :data:`_MAX_PENDING_FRAMES` frames wait for it: memory stays flat however
    long the run. :meth:`finish` adds the rest of the trace, the summary's totals and the
    index.

    ``info``: the run's metadata (scenario, seed, commit, MCU backend, ...: strings), written
    as the file's "mobigrasp" metadata record; ``camera``: the pinhole intrinsics (``f_px``,
    ``u0_px``, ``v0_px``, ``width``, ``height``) for /camera/calibration. A channel is
    registered with its first message: the file has no empty channel.

    :meth:`on_mcu_bytes` is told what the MCU wrote to the host's line, for a run whose trace
    does not hold it (``run``; ``sim``'s trace has the wire decoded): its Telemetry frames
    become /mcu/encoders and /mcu/sonars, as in ``sim``, and the trace stays as it was."""

    def __init__(self, path: Path | None = None, trace: Path | None = None,
                 info: dict[str, str] | None = None, camera: dict | None = None) -> None:
        self.info = {str(k): str(v) for k, v in (info or {}).items()}
        self.camera = camera
        self.counts = dict.fromkeys(TOPICS, 0)
        self._seq = 0
        self._next_chunk_us = CHUNK_PERIOD_US
        self._topics: _Topics | None = None
        self._trace_fh = None
        self._partial = ""
        self._pending: list[Future] = []
        self._worker: ThreadPoolExecutor | None = None
        self._writer = None  # until start()
        self._mcu_bytes: list[tuple[int, bytes]] = []  # (t_us, bytes) since the last frame
        self._mcu_batch = 0
        self._mcu_parser = None  # the worker's FrameParser of the MCU's bytes
        if path is not None:
            self.start(path, trace)

    def start(self, path: Path, trace: Path | None = None) -> None:
        """Open ``path`` (trace.jsonl beside it, or ``trace``, is followed): for a caller that
        knows the run folder only once the run has taken it (``sim``)."""
        from mcap.writer import CompressionType, Writer

        self.path = Path(path)
        self._trace_path = Path(trace) if trace is not None else self.path.with_name(
            "trace.jsonl")
        self._fh = self.path.open("wb")
        self._writer = Writer(self._fh, chunk_size=CHUNK_BYTES,
                              compression=CompressionType.ZSTD)
        self._writer.start(profile="", library="mobigrasp")
        if self.info:
            self._writer.add_metadata("mobigrasp", self.info)
        self._schema_ids: dict[str, int] = {}
        self._channels: dict[str, int] = {}

    def _channel(self, topic: str) -> int:
        """The channel of ``topic``, registered (with its schema) on first use."""
        if topic not in self._channels:
            name = TOPICS[topic]
            if name not in self._schema_ids:
                self._schema_ids[name] = self._writer.register_schema(
                    name=name, encoding="jsonschema", data=json.dumps(SCHEMAS[name]).encode())
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="json", schema_id=self._schema_ids[name])
        return self._channels[topic]

    def on_frame(self, seq: int, capture_us: int, rgb: np.ndarray) -> None:
        """Queue one frame (RGB, as the rig renders it; the rig does not reuse the array). The
        first frame of a simulated second returns once the file holds everything before it."""
        capture_us = int(capture_us)
        chunk_end = capture_us >= self._next_chunk_us
        if chunk_end:
            self._next_chunk_us = capture_us - capture_us % CHUNK_PERIOD_US + CHUNK_PERIOD_US
        self._submit(self._frame, capture_us, rgb, self._take_mcu_bytes(), chunk_end)
        if chunk_end:  # the second's chunk on the disk before the run goes past it
            self._wait_pending(0)

    def on_mcu_bytes(self, t_us: int, data: bytes) -> None:
        """What the MCU wrote to the host's line at simulated ``t_us`` (the rig's port)."""
        self._mcu_bytes.append((int(t_us), bytes(data)))
        self._mcu_batch += len(data)
        if self._mcu_batch >= _MCU_BATCH_BYTES:
            self._submit(self._telemetry, self._take_mcu_bytes())

    def _take_mcu_bytes(self) -> list[tuple[int, bytes]]:
        taken, self._mcu_bytes, self._mcu_batch = self._mcu_bytes, [], 0
        return taken

    def _submit(self, job, *args) -> None:
        """``job(*args)`` on the writer's thread, at most :data:`_MAX_PENDING_FRAMES` queued."""
        if self._worker is None:
            self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="mcap")
        while self._pending and self._pending[0].done():
            self._pending.pop(0).result()  # (raises what writing it raised)
        self._wait_pending(_MAX_PENDING_FRAMES - 1)
        self._pending.append(self._worker.submit(job, *args))

    def _wait_pending(self, keep: int) -> None:
        """Wait until at most ``keep`` jobs are queued (raising what one raised)."""
        while len(self._pending) > keep:
            self._pending.pop(0).result()

    def _frame(self, capture_us: int, rgb: np.ndarray, mcu_bytes: list[tuple[int, bytes]],
               chunk_end: bool) -> None:
        jpeg = _jpeg(rgb)
        self._follow_trace()
        self._telemetry(mcu_bytes)
        self._add(capture_us, "/camera/image", image_message(capture_us, jpeg))
        if chunk_end:  # the second's chunk onto the disk
            self._writer.flush()

    def _telemetry(self, mcu_bytes: list[tuple[int, bytes]]) -> None:
        """The encoder and sonar topics of the MCU's bytes (the writer's thread)."""
        if not mcu_bytes or self._writer is None:
            return
        if self._mcu_parser is None:
            from mobigrasp.protocol.frame import FrameParser

            self._mcu_parser = FrameParser()
        for t_us, data in mcu_bytes:
            for frame in self._mcu_parser.feed(data):
                for m in telemetry_messages(t_us, frame):
                    self._add(*m)

    def _add(self, t_us: int, topic: str, msg: dict) -> None:
        ns = int(t_us) * 1000
        self._writer.add_message(channel_id=self._channel(topic), log_time=ns, publish_time=ns,
                                 sequence=self._seq, data=json.dumps(
                                     msg, separators=(",", ":"), allow_nan=False).encode())
        self._seq += 1
        self.counts[topic] += 1

    def _follow_trace(self) -> None:
        """Convert the complete trace lines written since the last call."""
        if self._trace_fh is None:
            if not self._trace_path.is_file():
                return
            self._trace_fh = self._trace_path.open(encoding="utf-8", errors="replace")
        while True:
            line = self._trace_fh.readline()
            if not line:
                return
            if not line.endswith("\n"):  # written half: the rest comes with the next call
                self._partial += line
                continue
            line, self._partial = self._partial + line, ""
            try:
                event = json.loads(line)
            except json.JSONDecodeError:
                continue
            self._event(event)

    def _event(self, event: dict) -> None:
        if self._topics is None:
            if event.get("ev") != "start":
                return
            self._topics = _Topics(event, self.camera)
            for m in self._topics.first():
                self._add(*m)
        for m in self._topics.event(event):
            self._add(*m)

    def finish(self, summary: dict | None = None) -> dict[str, int]:
        """Write what is left and close the file; the message count per topic (nothing
        written when it was never started)."""
        pending, self._pending = self._pending, []
        for future in pending:
            future.result()
        if self._worker is not None:
            self._worker.shutdown()
            self._worker = None
        if self._writer is None:
            return self.counts
        self._follow_trace()
        self._telemetry(self._take_mcu_bytes())
        if self._topics is None:  # no trace: the scene of an empty start
            self._topics = _Topics({})
            for m in self._topics.first():
                self._add(*m)
        if summary is not None:
            self._add(*self._topics.end(summary))
        self._writer.finish()
        self._fh.close()
        if self._trace_fh is not None:
            self._trace_fh.close()
        return self.counts


def read_messages(path: Path) -> list[tuple[str, int, dict]]:
    """(topic, log time ns, message) of every message in a trace.mcap, also of one a kill left
    unfinished (no index, a torn last chunk): read as a stream up to the last whole record."""
    from mcap.exceptions import McapError
    from mcap.records import Channel, Message
    from mcap.stream_reader import StreamReader

    channels: dict[int, str] = {}
    out: list[tuple[str, int, dict]] = []
    with Path(path).open("rb") as fh:
        try:
            for record in StreamReader(fh, skip_magic=False).records:  # chunks opened
                if isinstance(record, Channel):
                    channels[record.id] = record.topic
                elif isinstance(record, Message):
                    out.append((channels[record.channel_id], record.log_time,
                                json.loads(record.data)))
        except (McapError, EOFError, ValueError):
            pass  # the end of what a killed run wrote
    return out
