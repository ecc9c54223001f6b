"""JSON schemas of the MCAP channels (services/mcap_out.py): the Foxglove message types by name.

Foxglove picks its panels by the schema *name* (``foxglove.CompressedImage`` goes to the Image
panel, ``foxglove.SceneUpdate`` to the 3D panel, ...); the JSON encoding of those types is
documented at docs.foxglove.dev ("Message schemas"): times are ``{"sec", "nsec"}``, byte fields
base64 strings, enums integers. The schemas below hold the fields mobigrasp writes, typed as that
documentation types them; the numeric channels have mobigrasp's own small schemas.
"""

from __future__ import annotations

TIME = {"type": "object", "properties": {"sec": {"type": "integer", "minimum": 0},
                                         "nsec": {"type": "integer", "minimum": 0}}}
VEC3 = {"type": "object", "properties": {k: {"type": "number"} for k in "xyz"}}
QUAT = {"type": "object", "properties": {k: {"type": "number"} for k in "xyzw"}}
POSE = {"type": "object", "properties": {"position": VEC3, "orientation": QUAT}}
COLOR = {"type": "object", "properties": {k: {"type": "number"} for k in ("r", "g", "b", "a")}}
POINT2 = {"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}}}


def _obj(title: str, **props) -> dict:
    return {"title": title, "type": "object", "properties": props}


def _array(item: dict) -> dict:
    return {"type": "array", "items": item}


NUMBER = {"type": "number"}
NUMBERS = _array({"type": ["number", "null"]})

SCHEMAS: dict[str, dict] = {
    "foxglove.CompressedImage": _obj(
        "foxglove.CompressedImage", timestamp=TIME, frame_id={"type": "string"},
        data={"type": "string", "contentEncoding": "base64"}, format={"type": "string"}),
    "foxglove.ImageAnnotations": _obj(
        "foxglove.ImageAnnotations",
        circles=_array(_obj("foxglove.CircleAnnotation", timestamp=TIME, position=POINT2,
                            diameter=NUMBER, thickness=NUMBER, fill_color=COLOR,
                            outline_color=COLOR)),
        points=_array(_obj("foxglove.PointsAnnotation", timestamp=TIME,
                           type={"type": "integer"}, points=_array(POINT2),
                           outline_color=COLOR, thickness=NUMBER)),
        texts=_array(_obj("foxglove.TextAnnotation", timestamp=TIME, position=POINT2,
                          text={"type": "string"}, font_size=NUMBER, text_color=COLOR,
                          background_color=COLOR))),
    "foxglove.FrameTransform": _obj(
        "foxglove.FrameTransform", timestamp=TIME, parent_frame_id={"type": "string"},
        child_frame_id={"type": "string"}, translation=VEC3, rotation=QUAT),
    "foxglove.SceneUpdate": _obj(
        "foxglove.SceneUpdate",
        deletions=_array(_obj("foxglove.SceneEntityDeletion", timestamp=TIME,
                              type={"type": "integer"}, id={"type": "string"})),
        entities=_array(_obj(
            "foxglove.SceneEntity", timestamp=TIME, frame_id={"type": "string"},
            id={"type": "string"}, lifetime=TIME, frame_locked={"type": "boolean"},
            metadata=_array(_obj("foxglove.KeyValuePair", key={"type": "string"},
                                 value={"type": "string"})),
            arrows=_array({"type": "object"}), triangles=_array({"type": "object"}),
            models=_array({"type": "object"}),
            cubes=_array(_obj("foxglove.CubePrimitive", pose=POSE, size=VEC3, color=COLOR)),
            cylinders=_array(_obj("foxglove.CylinderPrimitive", pose=POSE, size=VEC3,
                                  bottom_scale=NUMBER, top_scale=NUMBER, color=COLOR)),
            spheres=_array(_obj("foxglove.SpherePrimitive", pose=POSE, size=VEC3,
                                color=COLOR)),
            lines=_array(_obj("foxglove.LinePrimitive", type={"type": "integer"}, pose=POSE,
                              thickness=NUMBER, scale_invariant={"type": "boolean"},
                              points=_array(VEC3), color=COLOR)),
            texts=_array(_obj("foxglove.TextPrimitive", pose=POSE,
                              billboard={"type": "boolean"}, font_size=NUMBER,
                              scale_invariant={"type": "boolean"}, color=COLOR,
                              text={"type": "string"}))))),
    "foxglove.Log": _obj(
        "foxglove.Log", timestamp=TIME, level={"type": "integer", "minimum": 0, "maximum": 5},
        message={"type": "string"}, name={"type": "string"}, file={"type": "string"},
        line={"type": "integer"}),
    "mobigrasp.Joints": _obj("mobigrasp.Joints", joints_rad=NUMBERS, gripper=NUMBER,
                             roll_rad=NUMBER, wrist_rad=NUMBER, elbow_rad=NUMBER,
                             shoulder_rad=NUMBER, waist_rad=NUMBER),
    "mobigrasp.Wheels": _obj("mobigrasp.Wheels", left_mmps=NUMBER, right_mmps=NUMBER),
    "mobigrasp.Fuzzy": _obj("mobigrasp.Fuzzy", e_mrad=NUMBER, e_c_mrad_s=NUMBER,
                            u_mrad=NUMBER),
    "mobigrasp.Load": _obj("mobigrasp.Load", load=NUMBER, window_us=NUMBER),
    "mobigrasp.ProtocolCounters": _obj(
        "mobigrasp.ProtocolCounters", nacks=NUMBER, reliable_failed=NUMBER,
        output_rejected=NUMBER, mcu_resets_seen=NUMBER, deadline_misses=NUMBER,
        frames_dropped=NUMBER, tx_frames=NUMBER, rx_frames=NUMBER, crc_errors=NUMBER,
        retransmits=NUMBER),
    # the serial line decoded (trace "wire" events): any message with its fields
    "mobigrasp.WireMessage": _obj("mobigrasp.WireMessage", timestamp=TIME,
                                  seq={"type": "integer"}, msg={"type": "string"},
                                  fields={"type": "object"}, error={"type": "string"}),
    "mobigrasp.Nack": _obj("mobigrasp.Nack", timestamp=TIME, acked_seq={"type": "integer"},
                           reason={"type": "string"}, count={"type": "integer"}),
    "mobigrasp.WatchdogTrip": _obj("mobigrasp.WatchdogTrip", timestamp=TIME,
                                   trips={"type": "integer"}),
}
