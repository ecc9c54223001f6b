"""``mobigrasp bench fuzz`` at small N: mutated inputs into the firmware's parser and dispatch
give no crash, lose no frame after a corruption that ends at a 0x00, recover the frame after a
lost delimiter, and never leave the firmware outside its limits."""

import json
import subprocess
import sys

from mobigrasp.tools.benches import fuzz


def test_small_fuzz_run_has_no_crash_no_loss_and_no_limit_violation():
    out = fuzz.fuzz(1500, seed=3)
    assert out["inputs"] == 1500
    assert out["crashes"] == 0, out["first_crash"]
    assert out["frames_lost_after_corruption"] == 0
    assert out["limit_violations"] == 0
    assert out["never_sent_actuated"] <= out["frames_never_sent"]
    # the inputs were really damaged, the damage was seen, and the frames still flowed
    assert all(n > 0 for n in out["mutations"].values())
    parser = out["parser"]
    assert parser["crc_errors"] + parser["cobs_errors"] > 500
    assert out["lost_delimiter_inputs"] > 100
    assert parser["recovered"] >= out["lost_delimiter_inputs"] - out[
        "frames_lost_after_lost_delimiter"]
    assert out["frames_lost_after_lost_delimiter"] == 0
    assert out["frames_delivered"] > 0.6 * out["frames_sent"]


def test_fuzz_counts_a_parser_that_loses_frames(monkeypatch):
    # the loss counter is live: a parser that drops every other frame is caught
    from mobigrasp.protocol.frame import FrameParser

    real = FrameParser.feed

    def lossy(self, chunk):
        return real(self, chunk)[::2]
    monkeypatch.setattr(FrameParser, "feed", lossy)
    out = fuzz.fuzz(200, seed=3)
    assert out["frames_lost_after_corruption"] > 0


def test_bench_fuzz_command_writes_json(tmp_path):
    path = tmp_path / "fuzz.json"
    proc = subprocess.run([sys.executable, "-m", "mobigrasp", "bench", "fuzz", "--inputs", "200",
                           "--json", str(path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(path.read_text())
    assert data["bench"] == "fuzz" and data["inputs"] == 200 and data["crashes"] == 0
    assert "inputs_per_s" in proc.stdout
