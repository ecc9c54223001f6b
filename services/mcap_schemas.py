"""JSON schemas of the MCAP channels (services/mcap_out.py): the Foxglove message types by name.

Foxglove picks its panels by the schema *name* (``foxglove.CompressedImage`` goes to the Image
panel, ``foxglove.SceneUpdate`` to the 3D panel, ...). The ``foxglove.*`` schemas are the
published ones, unchanged (``services/foxglove_schemas/``, package data): a reader validates
against the real types. The numeric channels have mobigrasp's own small schemas.
"""

from __future__ import annotations

import json
from importlib.resources import files

TIME = {"type": "object", "properties": {"sec": {"type": "integer", "minimum": 0},
                                         "nsec": {"type": "integer", "minimum": 0}}}
FOXGLOVE_TYPES = ("CompressedImage", "ImageAnnotations", "FrameTransform", "SceneUpdate", "Log",
                  "CameraCalibration")


def _obj(title: str, **props) -> dict:
    return {"title": title, "type": "object", "properties": props}


def _array(item: dict) -> dict:
    return {"type": "array", "items": item}


def _foxglove(name: str) -> dict:
    folder = files("mobigrasp.services") / "foxglove_schemas"
    return json.loads((folder / f"foxglove.{name}.json").read_text(encoding="utf-8"))


NUMBER = {"type": "number"}
OPT_NUMBER = {"type": ["number", "null"]}  # a figure the run did not have (not computed yet)
NUMBERS = _array({"type": ["number", "null"]})
INTEGERS = _array({"type": "integer"})

SCHEMAS: dict[str, dict] = {
    **{f"foxglove.{name}": _foxglove(name) for name in FOXGLOVE_TYPES},
    "mobigrasp.Joints": _obj("mobigrasp.Joints", joints_rad=NUMBERS, gripper=NUMBER,
                             roll_rad=NUMBER, wrist_rad=NUMBER, elbow_rad=NUMBER,
                             shoulder_rad=NUMBER, waist_rad=NUMBER),
    "mobigrasp.Wheels": _obj("mobigrasp.Wheels", left_mmps=NUMBER, right_mmps=NUMBER),
    "mobigrasp.Fuzzy": _obj("mobigrasp.Fuzzy", e_mrad=OPT_NUMBER, e_c_mrad_s=OPT_NUMBER,
                            u_mrad=OPT_NUMBER),
    "mobigrasp.Load": _obj("mobigrasp.Load", load=NUMBER, window_us=OPT_NUMBER),
    "mobigrasp.ProtocolCounters": _obj(
        "mobigrasp.ProtocolCounters", nacks=NUMBER, reliable_failed=NUMBER,
        output_rejected=NUMBER, mcu_resets_seen=NUMBER, deadline_misses=NUMBER,
        frames_dropped=NUMBER, tx_frames=OPT_NUMBER, rx_frames=OPT_NUMBER,
        crc_errors=OPT_NUMBER, retransmits=OPT_NUMBER),
    # the serial line decoded (trace "wire" events): any message with its fields
    "mobigrasp.WireMessage": _obj("mobigrasp.WireMessage", timestamp=TIME,
                                  seq={"type": "integer"}, msg={"type": "string"},
                                  fields={"type": "object"}, error={"type": "string"}),
    "mobigrasp.Nack": _obj("mobigrasp.Nack", timestamp=TIME, acked_seq={"type": "integer"},
                           reason={"type": "string"}, count={"type": "integer"}),
    "mobigrasp.WatchdogTrip": _obj("mobigrasp.WatchdogTrip", timestamp=TIME,
                                   trips={"type": "integer"}),
    # what the MCU reports in TELEMETRY (docs/protocol.md 0x20), on their own topics
    "mobigrasp.Encoders": _obj("mobigrasp.Encoders", timestamp=TIME, enc_left=NUMBER,
                               enc_right=NUMBER),
    "mobigrasp.Sonars": _obj("mobigrasp.Sonars", timestamp=TIME, sonar_mm=INTEGERS),
}
