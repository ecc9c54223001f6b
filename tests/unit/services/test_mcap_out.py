"""trace.mcap read back with the mcap reader: every topic, its schema and its message count
against the run's trace; log times are simulated time; the arm's /tf chain lands the camera
where the world put it."""

import base64
import json
import math

import cv2
import jsonschema
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


# the MCU's last telemetry frames may still wait for the line when a run ends: at most this
# many are sent (summary "mcu" telemetry_sent) and not on the host's line
TELEMETRY_UNSENT_MAX = 2


def expected_counts(events: list[dict], summary: dict) -> dict:
    """What each topic must hold, counted from the trace and the summary alone (the
    telemetry topics: the MCU's count, see :data:`TELEMETRY_UNSENT_MAX`)."""
    truth = [e for e in events if e["ev"] == "truth" and e.get("x_m") is not None]
    with_joints = [e for e in truth if e.get("joints_rad")]
    n = {ev: sum(e["ev"] == ev for e in events) for ev in {e["ev"] for e in events}}
    details = [e for e in events if e["ev"] == "detail"]
    return {
        "/camera/image": summary["frames_captured"],
        "/camera/calibration": 1,
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
        "/mcu/encoders": summary["mcu"]["telemetry_sent"],
        "/mcu/sonars": summary["mcu"]["telemetry_sent"],
    }


@pytest.mark.parametrize("scenario", ["paper000-exp1", "paper001-sim1", "paper002-marker"])
def test_every_topic_schema_and_count_matches_the_trace(short_runs, scenario):
    folder = short_runs[scenario]
    events = read_trace(folder / "trace.jsonl")
    summary = json.loads((folder / "summary.json").read_text())
    got, mcap_summary = _read(folder / "trace.mcap")
    expected = expected_counts(events, summary)
    # a channel exists only for a topic that has messages: no empty channel in the file
    assert {ch.topic for ch in mcap_summary.channels.values()} == {
        t for t, n in expected.items() if n}
    counts = {topic: 0 for topic in TOPICS}
    validators = {name: jsonschema.Draft7Validator(schema) for name, schema in SCHEMAS.items()}
    for schema, schema_enc, topic, msg_enc, log_ns, pub_ns, msg in got:
        assert schema == TOPICS[topic] and schema_enc == "jsonschema" and msg_enc == "json"
        assert log_ns == pub_ns
        # every message is valid against its schema (the published Foxglove ones: full types)
        errors = [e.message for e in validators[schema].iter_errors(msg)]
        assert not errors, (topic, errors[:3])
        assert set(msg) <= set(SCHEMAS[schema]["properties"]), (topic, set(msg))
        if "timestamp" in msg:
            assert msg["timestamp"]["sec"] * 10**9 + msg["timestamp"]["nsec"] <= log_ns
        counts[topic] += 1
    for topic, name in SCHEMA_OF.items():
        assert TOPICS[topic] == name
    # each TELEMETRY the host was sent gives one message on each topic, as in sim's file
    for topic in ("/mcu/encoders", "/mcu/sonars"):
        assert 0 <= expected.pop(topic) - counts.pop(topic) <= TELEMETRY_UNSENT_MAX, topic
    assert counts == expected
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


def test_the_scene_shows_the_robot_and_the_file_says_which_run(short_runs):
    """/scene carries the robot's base and arm links, frame-locked to the /tf frames; the
    camera's calibration is the scenario's pinhole; the metadata names the run."""
    from mobigrasp.mcu_sim.world.arm import ARM_BY_METHOD
    from mobigrasp.services.run_job import resolve_scenario

    folder = short_runs["paper001-sim1"]
    summary = json.loads((folder / "summary.json").read_text())
    got, _ = _read(folder / "trace.mcap")
    scene = [g[6] for g in got if g[2] == "/scene"][0]
    robot = {e["id"]: e for e in scene["entities"] if e["id"].startswith("robot/")}
    assert set(robot) == {"robot/base", "robot/upper_arm", "robot/forearm", "robot/wrist"}
    assert all(e["frame_locked"] and e["frame_id"] == i.split("/")[1] for i, e in robot.items())
    geom = ARM_BY_METHOD["001"]
    assert robot["robot/forearm"]["cubes"][0]["size"]["x"] == pytest.approx(geom.l2)
    assert robot["robot/base"]["cylinders"][0]["size"]["x"] > 0.2
    cal = [g[6] for g in got if g[2] == "/camera/calibration"]
    assert len(cal) == 1 and (cal[0]["width"], cal[0]["height"]) == (320, 240)
    cam = resolve_scenario("paper001-sim1")[1].camera
    assert cal[0]["K"][0] == cam.f_px and cal[0]["K"][2] == cam.u0_px
    with open(folder / "trace.mcap", "rb") as fh:
        meta = {m.name: m.metadata for m in make_reader(fh).iter_metadata()}
    assert meta["mobigrasp"]["scenario"] == "paper001-sim1"
    assert meta["mobigrasp"]["seed"] == str(summary["seed"])
    assert meta["mobigrasp"]["mcu_backend"] == "python" and meta["mobigrasp"]["commit"]


def test_telemetry_on_the_wire_becomes_encoder_and_sonar_topics():
    from mobigrasp.services.mcap_out import wire_messages

    fields = {"enc_left": 10, "enc_right": -4, "sonar_mm": [300, 65535, 1200, 800, 500],
              "watchdog_trips": 0}
    out = dict(wire_messages({"t_us": 2_000_000, "dir": "to_host", "seq": 3,
                              "msg": "Telemetry", "fields": fields}, {}))
    assert out["/mcu/encoders"]["enc_left"] == 10 and out["/mcu/encoders"]["enc_right"] == -4
    assert out["/mcu/sonars"]["sonar_mm"] == [300, 65535, 1200, 800, 500]
    for topic in ("/mcu/encoders", "/mcu/sonars"):
        jsonschema.validate(out[topic], SCHEMAS[TOPICS[topic]])


def _telemetry(t_us: int, enc: int, seq: int) -> bytes:
    from mobigrasp.protocol.messages import Telemetry, encode_message

    return encode_message(Telemetry(time_us=t_us, enc_left=enc, enc_right=-enc,
                                    servo_us=(1500,) * 6, sonar_mm=(300, 400, 500, 600, 700),
                                    flags=0, crc_errors=0, overruns=0, limit_hits=0,
                                    watchdog_trips=0), seq)


def test_the_mcu_bytes_of_a_run_become_encoder_and_sonar_topics(tmp_path):
    """What the MCU writes to the host's line, in pieces cut anywhere and with garbage
    between frames, gives one /mcu/encoders and one /mcu/sonars message per TELEMETRY at the
    write's time, the same messages sim's wire events give; the trace is not read for them."""
    from mobigrasp.services.mcap_out import McapLog, read_messages, wire_messages

    (tmp_path / "trace.jsonl").write_text('{"ev":"start","t_us":0}\n')
    log = McapLog(tmp_path / "trace.mcap")
    wire = b"".join(_telemetry(20_000 * k, 7 * k, k) for k in range(1, 6))
    wire = wire[:30] + b"\x13\x37\x00" + wire[30:]  # a torn frame: the parser resyncs
    for k, at in enumerate(range(0, len(wire), 23)):
        log.on_mcu_bytes(5_000 * (k + 1), wire[at:at + 23])
    log.on_frame(0, 0, np.zeros((240, 320, 3), np.uint8))
    log.finish()
    got = read_messages(tmp_path / "trace.mcap")
    enc = [(t, m) for topic, t, m in got if topic == "/mcu/encoders"]
    sonar = [m for topic, _, m in got if topic == "/mcu/sonars"]
    # the frame torn by the garbage is lost, as the host's parser would lose it
    assert 4 <= len(enc) == len(sonar) <= 5
    assert [m["enc_left"] for _, m in enc][-3:] == [21, 28, 35]
    assert all(m["enc_right"] == -m["enc_left"] for _, m in enc)
    assert all(m["sonar_mm"] == [300, 400, 500, 600, 700] for m in sonar)
    assert [t for t, _ in enc] == sorted(t for t, _ in enc) and enc[0][0] > 0
    validators = {t: jsonschema.Draft7Validator(SCHEMAS[TOPICS[t]])
                  for t in ("/mcu/encoders", "/mcu/sonars")}
    for topic, _, m in got:
        if topic in validators:
            assert not list(validators[topic].iter_errors(m))
    # the same message as a sim's wire event of that telemetry
    t_ns, first = enc[-1]
    fields = {"enc_left": first["enc_left"], "enc_right": first["enc_right"],
              "sonar_mm": [300, 400, 500, 600, 700], "watchdog_trips": 0}
    from_wire = dict(wire_messages({"t_us": t_ns // 1000, "dir": "to_host", "seq": 5,
                                    "msg": "Telemetry", "fields": fields}, {}))
    assert from_wire["/mcu/encoders"] == first
