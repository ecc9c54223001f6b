"""A folder belongs to one run, sim session or campaign: a second one is refused (exit 2, one
line) and changes nothing; only files mobigrasp listed in the folder's marker are ever removed;
a campaign's resume never repeats or loses a row (cosim/run_folder.py, services/campaign.py)."""

from __future__ import annotations

import json
import socket
from pathlib import Path

import pytest

from mobigrasp.cosim.run_folder import (
    CAMPAIGN_MARKER,
    RUN_FILES,
    RUN_MARKER,
    claim_run_folder,
    owned_files,
    record_written,
)
from mobigrasp.services.campaign import DAMAGED_FILE, ROWS_FILE, CampaignConfig, run_campaign
from mobigrasp.tools.cli import main

E = "paper000-exp1"
QUICK = ["--transport", "inproc", "--time-limit-s", "0.1", "--quiet", "--no-plots"]


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _first_run(out: Path):
    """A run folder held as a run in progress holds it, with its files written."""
    held = claim_run_folder(out, "x", 1)
    held.prepare(RUN_FILES)
    (out / "summary.json").write_text('{"status": "running"}\n')
    (out / "trace.jsonl").write_text('{"ev": "start", "t_us": 0}\n')
    return held


def _one_line(capsys) -> str:
    out = capsys.readouterr()
    lines = out.err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in out.err + out.out, out.err
    return lines[0]


def test_a_run_into_a_folder_another_run_holds_is_refused_and_changes_nothing(tmp_path,
                                                                               capsys):
    out = tmp_path / "run"
    with _first_run(out):
        before = _snapshot(out)
        assert main(["run", E, "--out", str(out)] + QUICK) == 2
        line = _one_line(capsys)
        assert str(out) in line and "in use" in line
        assert _snapshot(out) == before


def test_a_sim_into_a_folder_a_run_holds_is_refused_and_changes_nothing(tmp_path, capsys):
    out = tmp_path / "run"
    with _first_run(out):
        before = _snapshot(out)
        assert main(["sim", E, "--out", str(out), "--quiet"]) == 2
        assert "in use" in _one_line(capsys)
        assert _snapshot(out) == before


def test_a_sim_whose_camera_port_is_taken_leaves_the_earlier_session_folder_alone(tmp_path,
                                                                                  capsys):
    out = tmp_path / "session"
    _first_run(out).release()  # an earlier session, finished
    before = _snapshot(out)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        assert main(["sim", E, "--out", str(out), "--camera-port", str(port), "--quiet"]) == 2
    assert str(port) in _one_line(capsys)
    assert _snapshot(out) == before


def test_default_sim_sessions_take_a_free_port_and_their_own_folders(tmp_path):
    from mobigrasp.tools.cli import build_parser

    assert build_parser().parse_args(["sim", E]).camera_port == 0  # any free port
    root = tmp_path / "runs"
    with claim_run_folder(None, E, 1, runs_root=root, suffix="-sim", next_free=True) as a, \
            claim_run_folder(None, E, 1, runs_root=root, suffix="-sim", next_free=True) as b:
        assert a.path.name == f"{E}-1-sim" and b.path.name == f"{E}-1-sim-2"
    # let go: the default folder is the first again
    with claim_run_folder(None, E, 1, runs_root=root, suffix="-sim", next_free=True) as c:
        assert c.path.name == f"{E}-1-sim"


def test_only_files_the_marker_lists_are_removed_by_a_later_run(tmp_path):
    out = tmp_path / "run"
    with claim_run_folder(out, "x", 1) as held:
        held.prepare(RUN_FILES)
        record_written(out, "plots/trajectory.png")
        (out / "plots").mkdir()
        (out / "plots" / "trajectory.png").write_bytes(b"the run's")
    # the user's: a plot of their own, and one named as mobigrasp names its plots
    (out / "plots" / "mine.png").write_bytes(b"user")
    (out / "plots" / "joints.png").write_bytes(b"user joints")
    with claim_run_folder(out, "x", 1) as held:
        held.prepare(RUN_FILES)
    assert not (out / "plots" / "trajectory.png").exists()
    assert (out / "plots" / "mine.png").read_bytes() == b"user"
    assert (out / "plots" / "joints.png").read_bytes() == b"user joints"
    assert "plots/trajectory.png" not in owned_files(out)


def test_a_report_does_not_overwrite_a_plot_mobigrasp_did_not_write(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", E, "--out", str(out), "--transport", "inproc", "--time-limit-s",
                 "0.5", "--quiet", "--no-plots"]) in (0, 1)
    (out / "plots").mkdir(exist_ok=True)
    (out / "plots" / "trajectory.png").write_bytes(b"user")
    from mobigrasp.services.report import write_report

    write_report(out)
    assert (out / "plots" / "trajectory.png").read_bytes() == b"user"
    assert (out / "plots" / "joints.png").is_file()  # its own plots are written
    assert "plots/joints.png" in owned_files(out)
    capsys.readouterr()


def test_a_run_folder_holding_a_run_file_mobigrasp_did_not_write_is_refused(tmp_path, capsys):
    out = tmp_path / "run"
    _first_run(out).release()
    marker = out / RUN_MARKER
    marker.write_text(marker.read_text().replace("trace.jsonl\n", ""))  # not listed now
    before = _snapshot(out)
    assert main(["run", E, "--out", str(out)] + QUICK) == 2
    assert "trace.jsonl" in _one_line(capsys)
    assert _snapshot(out) == before


# --- campaigns ---------------------------------------------------------------------------------

def _fake(job: dict) -> dict:
    return {"status": "finished", "success": job["seed"] % 2 == 0, "task_state": "DONE",
            "sim_time_s": 1.0, "trace_sha256": f"sha-{job['seed']}", "protocol": {}}


class Counting:
    def __init__(self) -> None:
        self.seeds: list[int] = []

    def __call__(self, job: dict) -> dict:
        self.seeds.append(job["seed"])
        return _fake(job)


def test_campaign_out_into_a_folder_of_user_files_is_refused(tmp_path, capsys):
    victim = tmp_path / "mine"
    victim.mkdir()
    for name in ("campaign.json", ROWS_FILE, "campaign.png"):
        (victim / name).write_text("years of work")
    before = _snapshot(victim)
    assert main(["campaign", "--method", "000", "--runs", "1", "--out", str(victim)]) == 2
    line = _one_line(capsys)
    assert str(victim) in line and "not a mobigrasp campaign folder" in line
    assert _snapshot(victim) == before


def test_a_campaign_into_a_folder_another_holds_is_refused(tmp_path, capsys):
    out = tmp_path / "c"
    run_campaign(CampaignConfig("000", 1, jobs=1, out=out), run_fn=_fake)
    from mobigrasp.cosim.run_folder import OwnedFolder

    with OwnedFolder.take(out, CAMPAIGN_MARKER, "campaign"):
        before = _snapshot(out)
        assert main(["campaign", "--method", "000", "--runs", "1", "--out", str(out)]) == 2
        assert "in use" in _one_line(capsys)
        assert _snapshot(out) == before


def _rows(path: Path) -> list[dict]:
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_resume_with_a_damaged_first_row_reruns_only_that_seed_and_sets_it_aside(tmp_path):
    out = tmp_path / "c"
    run_campaign(CampaignConfig("000", 4, jobs=1, out=out), run_fn=_fake)
    path = out / ROWS_FILE
    lines = path.read_text().splitlines()
    path.write_text("\n".join(['{"seed": 0, "succ\x00ess": tr'] + lines[1:]) + "\n")
    counting = Counting()
    res = run_campaign(CampaignConfig("000", 4, jobs=1, out=out, resume=True),
                       run_fn=counting)
    assert counting.seeds == [0]  # the damaged row's seed only; the intact ones not again
    assert res["set_aside"] and f"{path}: line 1: damaged row" in res["set_aside"][0]
    assert sorted(r["seed"] for r in _rows(path)) == [0, 1, 2, 3]  # one row a seed
    assert (out / DAMAGED_FILE).read_text() == '{"seed": 0, "succ\x00ess": tr\n'
    again = Counting()
    res = run_campaign(CampaignConfig("000", 4, jobs=1, out=out, resume=True), run_fn=again)
    assert again.seeds == [] and res["set_aside"] == []
    assert sorted(r["seed"] for r in _rows(path)) == [0, 1, 2, 3]
    assert res["summary"]["runs"] == 4


def test_resume_sets_aside_a_second_row_of_a_seed(tmp_path):
    out = tmp_path / "c"
    run_campaign(CampaignConfig("000", 2, jobs=1, out=out), run_fn=_fake)
    path = out / ROWS_FILE
    path.write_text(path.read_text() + path.read_text().splitlines()[0] + "\n")
    counting = Counting()
    res = run_campaign(CampaignConfig("000", 2, jobs=1, out=out, resume=True), run_fn=counting)
    assert counting.seeds == [] and len(res["rows"]) == 2
    assert "line 3: a second row of seed 0" in res["set_aside"][0]
    assert len(_rows(path)) == 2


@pytest.mark.parametrize("change, key", [
    (lambda r: r.pop("success"), "success"),
    (lambda r: r.update(seed=[0]), "seed"),
    (lambda r: r.update(retransmits=10**400), "retransmits"),
    (lambda r: r.update(stop_latency_ms=[float("inf")]), "stop_latency_ms"),
])
def test_resume_with_a_malformed_row_is_exit_2_with_one_line(tmp_path, capsys, change, key):
    out = tmp_path / "c"
    run_campaign(CampaignConfig("000", 2, jobs=1, out=out), run_fn=_fake)
    path = out / ROWS_FILE
    rows = _rows(path)
    change(rows[1])
    text = "\n".join(json.dumps(r) for r in rows) + "\n"
    path.write_text(text)
    assert main(["campaign", "--method", "000", "--runs", "2", "--out", str(out),
                 "--resume", "--quiet"]) == 2
    line = _one_line(capsys)
    assert f"{path}: line 2" in line and key in line and len(line) < 400
    assert path.read_text() == text  # nothing rewritten, nothing run


def test_a_run_folder_of_an_earlier_version_is_taken_over_with_its_own_files(tmp_path):
    out = tmp_path / "old"
    (out / "plots").mkdir(parents=True)
    (out / RUN_MARKER).write_text("a mobigrasp run folder: `mobigrasp run` may replace the "
                                  "files it wrote here\n")  # one line, no list
    (out / "summary.json").write_text("{}")
    (out / "plots" / "joints.png").write_bytes(b"old plot")
    (out / "plots" / "mine.png").write_bytes(b"user")
    with claim_run_folder(out, "x", 1) as held:
        held.prepare(RUN_FILES)
    assert not (out / "summary.json").exists() and not (out / "plots" / "joints.png").exists()
    assert (out / "plots" / "mine.png").read_bytes() == b"user"
    assert owned_files(out) == list(RUN_FILES)


def test_a_second_run_on_the_folder_of_a_run_in_progress_is_refused(tmp_path, capsys):
    """Two `mobigrasp run` with the same --out at once: the second is refused and the first
    goes on to a summary that matches its own trace."""
    import signal

    from test_killed_runs import SAFETY_S, _wait_for_sim_time, running

    out = tmp_path / "run"
    with running(out) as first:
        _wait_for_sim_time(first, 2.0)
        assert main(["run", E, "--out", str(out)] + QUICK) == 2
        assert "in use" in _one_line(capsys)
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=SAFETY_S)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted" and summary["sim_time_s"] >= 2.0
    lines = (out / "trace.jsonl").read_text().splitlines()
    assert summary["trace_lines"] == len(lines) > 20


def test_run_check_refuses_a_folder_a_run_holds_and_changes_nothing(tmp_path, capsys):
    out = tmp_path / "run"
    with _first_run(out):
        before = _snapshot(out)
        assert main(["run", E, "--out", str(out), "--check"]) == 2
        line = _one_line(capsys)
        assert str(out) in line and "in use" in line
        assert _snapshot(out) == before


def test_run_check_passes_what_the_run_takes_and_leaves_no_folder(tmp_path, capsys,
                                                                  monkeypatch):
    monkeypatch.chdir(tmp_path)
    new = tmp_path / "deep" / "er" / "run"
    assert main(["run", E, "--out", str(new), "--check"]) == 0
    assert capsys.readouterr().out.strip().endswith(": ok")
    assert not (tmp_path / "deep").exists()  # created to be checked, removed again
    assert main(["run", E, "--check"]) == 0  # the default folder under runs/
    assert not (tmp_path / "runs").exists()
    earlier = tmp_path / "earlier"
    with _first_run(earlier):
        pass  # an earlier run's folder, no longer held: the run would replace its files
    before = _snapshot(earlier)
    assert main(["run", E, "--out", str(earlier), "--check"]) == 0
    assert _snapshot(earlier) == before
