"""A run writes only under its own folder and deletes only what mobigrasp wrote there.

Every case puts a victim folder outside the runs root (in tmp_path) and runs the real CLI in
process, for a fraction of a simulated second (in process, no plots): the victim must survive.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from mobigrasp.cosim.run_folder import (
    RUN_FILES,
    RUN_MARKER,
    RunFolderError,
    claim_run_folder,
    default_run_folder,
    safe_component,
)
from mobigrasp.resources import data_dir
from mobigrasp.tools.cli import main

SCENARIO = data_dir("mobigrasp.scenarios") / "paper000-exp1.toml"
QUICK = ["--transport", "inproc", "--time-limit-s", "0.1", "--quiet", "--no-plots"]


def _victim(root: Path, name: str = "victim") -> Path:
    """A folder that looks like a run folder of an older version (summary.json) plus a file of
    the user's: neither may be deleted."""
    v = root / name
    v.mkdir(parents=True)
    (v / "summary.json").write_text("{}\n")
    (v / "thesis.tex").write_text("years of work\n")
    return v


def prepare_run_folder(out, name, seed, **kw) -> Path:
    """Take and ready a run folder as a run does, then let it go."""
    with claim_run_folder(out, name, seed, **kw) as folder:
        return folder.prepare(RUN_FILES)


def _assert_intact(victim: Path) -> None:
    assert sorted(p.name for p in victim.iterdir()) == ["summary.json", "thesis.tex"]
    assert (victim / "thesis.tex").read_text() == "years of work\n"


def _scenario_named(tmp_path: Path, name: str) -> Path:
    text = SCENARIO.read_text().replace('name = "paper000-exp1"', f"name = {name!r}")
    assert f"name = {name!r}" in text
    path = tmp_path / "sc.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("kind", ["absolute", "relative", "parent", "mixed"])
def test_scenario_name_cannot_point_the_run_folder_elsewhere(tmp_path, monkeypatch, capsys,
                                                             kind):
    # the default folder is runs/<name>-<seed> (seed 1): unsanitised, these names would land on
    # the victim
    outside = tmp_path / "outside"
    victim = _victim(outside, "victim-1")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    if kind == "parent":  # runs/../victim-1 is work/victim-1
        victim = _victim(work, "victim-1")
    name = {"absolute": str(outside / "victim"),
            "relative": os.path.relpath(outside / "victim", work / "runs"),
            "parent": "../victim", "mixed": "../../outside/x/../victim"}[kind]
    code = main(["run", str(_scenario_named(tmp_path, name))] + QUICK)
    assert code in (0, 1), capsys.readouterr().err
    _assert_intact(victim)
    folders = list((work / "runs").iterdir())
    assert len(folders) == 1 and folders[0].parent == work / "runs"
    assert not folders[0].is_symlink() and folders[0].name.endswith("-1")
    assert (folders[0] / RUN_MARKER).is_file() and (folders[0] / "summary.json").is_file()


def test_out_with_a_summary_and_other_files_is_refused(tmp_path, capsys):
    victim = _victim(tmp_path)
    assert main(["run", "paper000-exp1", "--out", str(victim)] + QUICK) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(victim) in err[0] and "Traceback" not in err[0]
    _assert_intact(victim)


def test_out_with_only_a_summary_is_refused_without_the_marker(tmp_path, capsys):
    victim = tmp_path / "old"
    victim.mkdir()
    (victim / "summary.json").write_text("{}\n")
    assert main(["run", "paper000-exp1", "--out", str(victim)] + QUICK) == 2
    assert (victim / "summary.json").read_text() == "{}\n"
    capsys.readouterr()


def test_rerun_into_a_run_folder_replaces_only_its_own_files(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "paper000-exp1", "--out", str(out)] + QUICK) in (0, 1)
    assert (out / RUN_MARKER).is_file()
    (out / "notes.txt").write_text("mine\n")
    (out / "frames").mkdir(exist_ok=True)
    (out / "frames" / "holiday.png").write_bytes(b"png")
    # named as a snapshot, but the marker does not list it: not the run's to remove
    (out / "frames" / "000_0001000ms_SEARCH.png").write_bytes(b"look-alike")
    (out / "summary.json").write_text("stale")
    (out / "trace.jsonl").write_text("stale\n")
    assert main(["run", "paper000-exp1", "--out", str(out)] + QUICK) in (0, 1)
    assert (out / "notes.txt").read_text() == "mine\n"
    assert (out / "frames" / "holiday.png").read_bytes() == b"png"
    assert (out / "frames" / "000_0001000ms_SEARCH.png").read_bytes() == b"look-alike"
    assert (out / "summary.json").read_text() != "stale"
    assert (out / "trace.jsonl").read_text() != "stale\n"
    capsys.readouterr()


def test_an_empty_existing_folder_is_used_and_marked(tmp_path):
    out = tmp_path / "empty"
    out.mkdir()
    assert prepare_run_folder(out, "x", 1) == out
    assert (out / RUN_MARKER).is_file()


def test_out_that_is_a_symlink_to_a_run_folder_is_refused(tmp_path):
    real = tmp_path / "real"
    prepare_run_folder(real, "x", 1)
    (real / "summary.json").write_text("{}")
    link = tmp_path / "link"
    link.symlink_to(real)
    with pytest.raises(RunFolderError, match="symbolic link"):
        prepare_run_folder(link, "x", 1)
    assert (real / "summary.json").exists()


def test_default_folder_through_a_symlinked_name_is_refused(tmp_path):
    victim = _victim(tmp_path / "outside")
    root = tmp_path / "runs"
    root.mkdir()
    (root / "exp-1").symlink_to(victim)
    with pytest.raises(RunFolderError):
        prepare_run_folder(None, "exp", 1, runs_root=root)
    _assert_intact(victim)


@pytest.mark.parametrize("name, expected", [
    ("paper000-exp1", "paper000-exp1"), ("/tmp/x/victim", "_tmp_x_victim"), ("..", "_."),
    (".", "_"), ("a b/c", "a_b_c"), ("", "_"), (".hidden", "_hidden"), ("é", "_"),
])
def test_safe_component(name, expected):
    assert safe_component(name) == expected


def test_default_run_folder_is_one_component_under_the_root():
    for name in ("/etc", "../../..", "a/../../b", "x" * 1000, "\x00"):
        p = default_run_folder(name, 7, Path("runs"))
        assert p.parent == Path("runs") and len(p.parts) == 2 and len(p.name) <= 110


def test_sim_refuses_an_out_folder_that_is_not_a_run_folder(tmp_path, capsys):
    victim = _victim(tmp_path)
    assert main(["sim", "paper000-exp1", "--out", str(victim), "--camera-port", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(victim) in err[0]
    _assert_intact(victim)


def test_sim_default_folder_is_under_the_root(tmp_path):
    victim = _victim(tmp_path / "outside", "victim-1-sim")
    root = tmp_path / "runs"
    out = prepare_run_folder(None, str(tmp_path / "outside" / "victim"), 1, runs_root=root,
                             suffix="-sim")
    assert out.parent == root and out.name.endswith("-1-sim") and (out / RUN_MARKER).is_file()
    _assert_intact(victim)
