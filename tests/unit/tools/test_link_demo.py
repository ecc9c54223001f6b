import json
import platform

import pytest

from mobigrasp.tools.cli import main
from mobigrasp.tools.commands.link_demo import run_link_demo


def test_link_demo_round_trips_every_message():
    lines = []
    result = run_link_demo(40, out=lines.append)
    assert result["count"] == 40 and result["received"] == 40 and result["lost"] == 0
    assert 0 < result["rtt_ms_p50"] <= result["rtt_ms_p95"] <= result["rtt_ms_max"]
    assert lines[0].startswith("pty slave: /dev/")
    assert any("sent 40, received 40, lost 0" in line for line in lines)
    assert any("echo process exit 0" in line for line in lines)


def test_link_demo_and_demo_commands_exit_zero(capsys):
    assert main(["link-demo", "--count", "10"]) == 0
    assert "lost 0" in capsys.readouterr().out
    assert main(["demo", "--count", "5"]) == 0
    assert "runs the link demo" in capsys.readouterr().out


def test_bench_protocol_writes_json(tmp_path, capsys):
    path = tmp_path / "protocol.json"
    assert main(["bench", "protocol", "--frames", "500", "--repeat", "1", "--json",
                 str(path)]) == 0
    figures = json.loads(path.read_text())
    assert figures["bench"] == "protocol" and figures["frames"] == 500
    assert figures["parse_mb_per_s"] > 0 and figures["encode_mb_per_s"] > 0
    assert figures["line_rate_bytes_per_s"] == 11_520
    assert abs(figures["parse_x_line_rate"] * 11_520 / 1e6 - figures["parse_mb_per_s"]) < 1e-6
    out = capsys.readouterr().out
    assert "parse_mb_per_s" in out
    # which interpreter ran it (figures compare only between runs of the same one)
    py = figures["python"]
    assert py["version"] == platform.python_version() and py["executable"]
    assert "python.version" in out


@pytest.mark.parametrize("count", ["-1", "0", "nan", "1e400", "9" * 400])
def test_a_count_out_of_range_is_exit_2_in_one_line(count, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["link-demo", "--count", count])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "--count" in err[-1] and "Traceback" not in "".join(err)
    assert len(err[-1]) < 200
