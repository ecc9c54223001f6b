"""trace.mcap read back with the mcap reader: every topic, its schema and its message count
against the run's trace; log times are simulated time; the arm's /tf chain lands the camera
where the world put it."""

import base64
import json
import math

import cv2
import numpy as np
import pytest
from mcap.reader import make_reader

from mobigrasp.cosim.run_folder import read_trace
from mobigrasp.services.mcap_out import ARM_FRAMES, PROTOCOL_EVENTS, TOPICS
from mobigrasp.services.mcap_schemas import SCHEMAS

SCHEMA_OF = {
    "/camera/image": "foxglove.CompressedImage",
    "/camera/detections": "foxglove.ImageAnnotations",
    "/tf": "foxglove.FrameTransform",
    "/scene": "foxglove.SceneUpdate",
    "/task/state": "foxglove.Log",
}


def _read(path):
    with open(path, "rb") as fh:
        reader = make_reader(fh)
        got = [(schema.name, schema.encoding, channel.topic, channel.message_encoding,
                message.log_time, message.publish_time, json.loads(message.data))
               for schema, channel, message in reader.iter_messages(log_time_order=False)]
        fh.seek(0)
        summary = make_reader(fh).get_summary()
    return got, summary


def expected_counts(events: list[dict], summary: dict) -> dict:
    """What each topic must hold, counted from the trace and the summary alone."""
    truth = [e for e in events if e["ev"] == "truth" and e.get("x_m") is not None]
    with_joints = [e for e in truth if e.get("joints_rad")]
    n = {ev: sum(e["ev"] == ev for e in events) for ev in {e["ev"] for e in events}}
    details = [e for e in events if e["ev"] == "detail"]
    return {
        "/camera/image": summary["frames_captured"],
        "/camera/detections": n.get("detect", 0),
        "/tf": len(truth) + sum(bool(e.get("obj")) for e in truth)
        + len(ARM_FRAMES) * len(with_joints),
        "/scene": 1 + sum(isinstance(e.get("plan"), dict) for e in details),
        "/task/state": n.get("state", 0) + n.get("end", 0),
        "/joints": len(with_joints),
        "/wheels/commanded": n.get("wheels", 0),
        "/wheels/measured": len(truth) - 1,
        "/fuzzy": sum(isinstance(e.get("fuzzy"), dict) for e in details),
        "/arm9/load": n.get("load", 0),
        "/protocol/counters": 2 + sum(n.get(ev, 0) for ev in PROTOCOL_EVENTS),
        "/wire/to_mcu": 0, "/wire/to_host": 0, "/wire/nacks": 0, "/wire/watchdog": 0,
    }


@pytest.mark.parametrize("scenario", ["paper000-exp1", "paper001-sim1", "paper002-marker"])
def test_every_topic_schema_and_count_matches_the_trace(short_runs, scenario):
    folder = short_runs[scenario]
    events = read_trace(folder / "trace.jsonl")
    summary = json.loads((folder / "summary.json").read_text())
    got, mcap_summary = _read(folder / "trace.mcap")
    assert {ch.topic for ch in mcap_summary.channels.values()} == set(TOPICS)
    counts = {topic: 0 for topic in TOPICS}
    for schema, schema_enc, topic, msg_enc, log_ns, pub_ns, msg in got:
        assert schema == TOPICS[topic] and schema_enc == "jsonschema" and msg_enc == "json"
        assert log_ns == pub_ns
        # every field written is one its schema declares (the Foxglove types' field names)
        assert set(msg) <= set(SCHEMAS[schema]["properties"]), (topic, set(msg))
        if "timestamp" in msg:
            assert msg["timestamp"]["sec"] * 10**9 + msg["timestamp"]["nsec"] <= log_ns
        counts[topic] += 1
    for topic, name in SCHEMA_OF.items():
        assert TOPICS[topic] == name
    assert counts == expected_counts(events, summary)
    # the camera and the detections exist in this run, and the method's own channels
    assert counts["/camera/image"] > 10 and counts["/camera/detections"] > 10
    if scenario.startswith("paper001"):
        assert counts["/scene"] >= 2
    if scenario.startswith("paper002"):
        assert counts["/fuzzy"] > 10
    # log times are simulated time: within the run, and the state log at the state's t_us
    end_ns = int(round(summary["sim_time_s"] * 1e9))
    assert all(0 <= g[4] <= end_ns for g in got)
    states = [e for e in events if e["ev"] == "state"]
    logged = [(g[4], g[6]["message"]) for g in got if g[2] == "/task/state"]
    for e in states:
        assert (e["t_us"] * 1000, f"{e['from']} -> {e['to']}: {e['why']}") in logged


def test_images_are_jpeg_frames_and_detections_share_their_stamps(short_runs):
    got, _ = _read(short_runs["paper000-exp1"] / "trace.mcap")
    images = [g for g in got if g[2] == "/camera/image"]
    first = images[0][6]
    rgb = cv2.imdecode(np.frombuffer(base64.b64decode(first["data"]), np.uint8),
                       cv2.IMREAD_COLOR)
    assert first["format"] == "jpeg" and rgb.shape == (240, 320, 3)
    stamps = {(m["timestamp"]["sec"], m["timestamp"]["nsec"]) for *_, m in images}
    dets = [g[6] for g in got if g[2] == "/camera/detections"]
    found = [d for d in dets if d["circles"]]
    assert found, "the symbol is detected in this run"
    for d in found:  # Foxglove pairs annotations with the image of the same timestamp
        assert (d["circles"][0]["timestamp"]["sec"], d["circles"][0]["timestamp"]["nsec"]) \
            in stamps


def _rot(q):
    x, y, z, w = q["x"], q["y"], q["z"], q["w"]
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


@pytest.mark.parametrize("scenario", ["paper000-exp1", "paper002-marker"])
def test_tf_chain_puts_the_camera_where_the_world_did(short_runs, scenario):
    """world -> base -> ... -> camera composed from /tf equals the truth's camera_m, and the
    camera's z axis (OpenCV optical axis) points along l3: pitch alpha = theta2 + theta3 +
    theta4, heading the base's turned by -theta5."""
    folder = short_runs[scenario]
    events = read_trace(folder / "trace.jsonl")
    got, _ = _read(folder / "trace.mcap")
    by_time: dict[int, dict] = {}
    for g in got:
        if g[2] == "/tf":
            by_time.setdefault(g[4], {})[g[6]["child_frame_id"]] = g[6]
    checked = 0
    for e in (e for e in events if e["ev"] == "truth" and e.get("camera_m")):
        tfs = by_time[e["t_us"] * 1000]
        chain = ["base", *ARM_FRAMES]
        r, p = np.eye(3), np.zeros(3)
        for child in chain:
            tf = tfs[child]
            t = tf["translation"]
            p = p + r @ np.array([t["x"], t["y"], t["z"]])
            r = r @ _rot(tf["rotation"])
        assert p == pytest.approx(e["camera_m"], abs=2e-3), e["t_us"]
        j = e["joints_rad"]
        alpha, yaw = j[2] + j[3] + j[4], e["heading_rad"] - j[5]  # theta5 turns right
        axis = [math.cos(alpha) * math.cos(yaw), math.cos(alpha) * math.sin(yaw),
                math.sin(alpha)]
        assert r[:, 2] == pytest.approx(axis, abs=1e-6)
        checked += 1
    assert checked > 50
