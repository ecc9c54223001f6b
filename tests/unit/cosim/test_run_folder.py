"""Run folder pieces: trace hashing and flushing, summary, report and plots, CLI exit codes."""

import hashlib
import json

import cv2
import numpy as np
import pytest

from mobigrasp.cosim.run_folder import Snapshots, TraceWriter, read_trace, write_summary
from mobigrasp.services.report import write_report
from mobigrasp.tools.cli import main


def test_trace_is_flushed_per_line_and_hashed(tmp_path):
    tw = TraceWriter(tmp_path / "t.jsonl")
    tw.write({"ev": "a", "t_us": 1, "x": 0.1 + 0.2, "arr": np.arange(3), "n": float("nan")})
    # readable before close: a crash later loses nothing already written
    raw = (tmp_path / "t.jsonl").read_bytes()
    assert raw.count(b"\n") == 1
    tw.write({"ev": "b", "t_us": 2})
    tw.close()
    raw = (tmp_path / "t.jsonl").read_bytes()
    assert tw.sha256() == hashlib.sha256(raw).hexdigest()
    ev = read_trace(tmp_path / "t.jsonl")
    assert ev[0]["arr"] == [0, 1, 2] and ev[0]["n"] is None and ev[1]["ev"] == "b"
    with pytest.raises(ValueError, match="t_us"):
        tw.write({"ev": "no time"})


def test_read_trace_skips_torn_last_line(tmp_path):
    p = tmp_path / "t.jsonl"
    p.write_text('{"ev":"a","t_us":0}\n{"ev":"b","t_')
    assert [e["ev"] for e in read_trace(p)] == ["a"]


def _fake_run(folder):
    tw = TraceWriter(folder / "trace.jsonl")
    tw.write({"ev": "start", "t_us": 0, "obstacles": [
        {"shape": "circle", "x_m": 1.0, "y_m": 0.2, "radius_m": 0.2}]})
    for k in range(30):
        tw.write({"ev": "truth", "t_us": k * 100_000, "x_m": 0.05 * k, "y_m": 0.01 * k,
                  "joints_rad": [0, 0, -1.5, -1.0, 1.5, 0.01 * k], "obj": [1.5, 0.5, 0.0]})
    tw.write({"src": "host", "ev": "state", "t_us": 1_000_000, "from": "SEARCH",
              "to": "APPROACH", "why": "seen"})
    tw.write({"src": "host", "ev": "detail", "t_us": 1_000_000, "state": "APPROACH",
              "plan": {"candidates": [[[0, 0], [500, 100], [1000, 300]]],
                       "best": [[0, 0], [600, 50], [1200, 400]]}})
    tw.write({"src": "host", "ev": "detail", "t_us": 1_100_000, "state": "APPROACH",
              "fuzzy": {"e": 0.1, "e_c": -0.2, "u": 0.05}})
    tw.write({"ev": "load", "t_us": 0, "window_us": 500_000, "load": 0.4})
    tw.close()
    write_summary(folder / "summary.json", {"scenario": "x", "seed": 1, "success": True,
                                            "protocol": {"tx_frames": 3}})


def test_report_links_plots_and_frames(tmp_path):
    _fake_run(tmp_path)
    snaps = Snapshots(tmp_path / "frames")
    snaps.on_frame(4, 0, np.zeros((240, 320, 3), np.uint8))
    snaps.on_host_event({"ev": "detect", "seq": 4, "t_us": 5,
                         "results": {"radial_symbol": {"u_q4": 1600, "v_q4": 1920}}})
    snaps.on_host_event({"ev": "state", "t_us": 9, "from": "SEARCH", "to": "APPROACH"})
    assert len(snaps.written) == 1
    path = write_report(tmp_path)
    html = path.read_text()
    for name in ("trajectory.png", "joints.png", "bezier.png", "fuzzy.png", "arm9_load.png"):
        assert (tmp_path / "plots" / name).stat().st_size > 1000
        assert f"plots/{name}" in html
    assert f"frames/{snaps.written[0]}" in html
    assert "SUCCESS" in html


def test_summary_is_atomic_json(tmp_path):
    write_summary(tmp_path / "summary.json", {"a": float("inf"), "b": np.float32(1.5)})
    assert json.loads((tmp_path / "summary.json").read_text()) == {"a": None, "b": 1.5}


@pytest.mark.parametrize("argv", [
    ["run", "no-such-scenario"],
    ["run", "paper000-exp1", "--speed", "fast"],
    ["run", "paper000-exp1", "--speed", "-1"],
    ["run", "paper000-exp1", "--host-lag-quanta", "2"],
    ["run", "paper000-exp1", "--host-lag-quanta", "-1"],
])
def test_run_bad_input_exits_2(argv, tmp_path):
    try:
        code = main([*argv, "--out", str(tmp_path / "o")])
    except SystemExit as exc:  # argparse rejects a value outside an option's choices
        code = exc.code
    assert code == 2


def test_run_invalid_file_exits_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[scenario]\nname = "x"\nmethod = "000"\nseed = 1\ntime_limit_s = 5\n'
                   "[robot]\nx_m = 0\ny_m = 0\nheading_rad = 0\nwheels = 3\n")
    assert main(["run", str(bad), "--out", str(tmp_path / "o")]) == 2
    assert "bad.toml" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [
    ["run", "paper000-exp1", "--frobnicate"],
    ["run", "paper000-exp1", "--transport", "carrier-pigeon"],  # refused by argparse choices
])
def test_run_bad_option_exits_2(argv):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2


def test_scenarios_lists_the_six(capsys):
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    for name in ("paper000-exp1", "paper000-exp2", "paper001-sim1", "paper001-sim2",
                 "paper002-marker", "paper002-cylinder-moving"):
        assert name in out


def test_detection_points_of_every_detector_are_drawn():
    from mobigrasp.cosim.run_folder import detection_points

    pts = detection_points({"double_cross": {"u1_q4": 160, "v1_q4": 320, "u2_q4": 480, "v2_q4": 320,
                                    "um_q4": 320, "vm_q4": 320, "d_pixel_q4": 5},
                   "red_cylinder": {"u_c_q4": 32, "v_c_q4": 48}, "spoke": None})
    assert sorted(pts) == [(2, 3), (10, 20), (20, 20), (30, 20)]


def test_snapshots_are_written_in_the_background_and_waited_for(tmp_path):
    snaps = Snapshots(tmp_path / "frames", keep=3)
    for seq in range(5):
        rgb = np.full((24, 32, 3), 40 * seq, np.uint8)
        snaps.on_frame(seq, seq * 66_666, rgb)
        snaps.on_host_event({"ev": "state", "t_us": seq * 66_666 + 1, "from": "A", "to": "B"})
    names = snaps.written  # waits for the writer thread
    assert names == [f"{k:03d}_{k * 66_666 // 1000:07d}ms_B.png" for k in range(5)]
    for k, name in enumerate(names):
        img = cv2.imread(str(tmp_path / "frames" / name))
        assert img is not None and img.shape == (24, 32, 3)
        assert int(img[20, 30, 0]) == 40 * k  # the frame of its state change, in order
    snaps.on_host_event({"ev": "state", "t_us": 400_000, "from": "B", "to": "C"})  # and again
    assert len(snaps.written) == 6 and (tmp_path / "frames" / snaps.written[-1]).exists()
