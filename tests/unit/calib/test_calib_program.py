"""The host program's recorded run replayed on its ARMv4T ELF under unicorn (calib/program.py):
the C program writes the Python program's serial bytes and trace events quantum by quantum,
whole control steps and frame pipelines are timed against the model's charge, and a replay that
parts from the recording is caught."""

import dataclasses

import pytest

from mobigrasp import hostc
from mobigrasp.calib import arm, program
from mobigrasp.calib.arm import I64
from mobigrasp.host.app import HostConfig
from mobigrasp.services.corpus import record_steps

BASE_US = HostConfig().control_base_cycles // 400  # a control step's base charge, µs


@pytest.fixture(scope="module")
def elf():
    return program.build()


@pytest.fixture(scope="module")
def marker():
    """The first 1.2 s of paper002-marker, recorded: the HELLO, the handshake, SEARCH's first
    steps and the detectors' first frames."""
    return record_steps("paper002-marker", time_limit_s=1.2)


def test_the_replay_equals_the_python_program_and_times_whole_steps(elf, marker):
    ticks, frames = program.pick(marker, 2)
    assert len(ticks) == 2 and len(frames) == 2
    replay = program.Replay(program.ProgramArm9(elf), marker)
    samples = replay.run(ticks, frames)  # ReplayMismatch at the first quantum that differs
    assert replay.quanta == sum(1 for c in marker.calls if c[0] == "advance")
    assert sorted(s.t_us for s in samples if s.kind == "control") == sorted(ticks)
    assert sorted(s.t_us for s in samples if s.kind == "frame") == sorted(frames)
    for s in samples:
        us = s.timing.cycles / 400
        if s.kind == "control":  # the base charge and the protocol bytes'
            assert s.modelled_us >= BASE_US and 20 < us < 1000
        else:  # the double cross and the red cylinder on SEARCH's frames
            assert 0.8 <= s.modelled_us / us <= 1.25, (s.t_us, s.modelled_us, us)
        assert s.timing.instructions > 0 and 1.0 <= s.timing.cpi <= 3.0


def test_a_replay_that_parts_from_the_recording_is_caught(elf, marker):
    k = min(i for i, c in enumerate(marker.calls) if c[0] == "output" and c[1])
    calls = list(marker.calls)
    calls[k] = ("output", bytes([calls[k][1][0] ^ 1]) + calls[k][1][1:])
    bad = dataclasses.replace(marker, calls=calls)
    with pytest.raises(program.ReplayMismatch, match="serial bytes differ"):
        program.Replay(program.ProgramArm9(elf), bad).run(set(), set())


def test_the_stages_follow_the_methods_in_the_c_program(elf):
    """A method's rows appear once the C program has it (000 and 001 when they are ported)."""
    methods = program.methods_in_program(elf)
    listed = hostc.program_methods([str(hostc.executable())])  # the program's --list-methods
    assert methods == [m for m in program.SCENARIOS if m in listed] and "002" in methods
    assert program.stage_names("002") == ("control_step_002", "frame_pipeline_002")


def test_64_bit_arguments_take_even_register_pairs_and_aligned_stack_slots(elf):
    """AAPCS as gcc compiles it: mg_calib_take_output(app, int64, ptr, int) puts the int64 in
    r2:r3 and the rest on the stack; mg_app_on_frame's three int64 after the app go to r2:r3
    and two 8-aligned stack slots."""
    m = program.ProgramArm9(elf)
    p = program.HEAP_BASE + program.PROGRAM
    text = b'{"method": "002"}'
    assert m.call("mg_calib_program_open", p, m.write(program.HEAP_BASE + program.IO, text),
                  len(text), timed=False)[0] > 0
    m.call("mg_app_on_frame", p, I64(7), I64(1 << 40), I64(-5), 0, 320, 240, timed=False)
    assert m.call64("mg_calib_stage_us", p, 0) == 0
    # the frame queued at arrival -5 runs with the first advance: idle (no detector yet)
    m.call("mg_app_advance_to", p, I64(1), timed=False)
    n, _ = m.call("mg_calib_take_output", p, I64(1 << 33), program.HEAP_BASE + program.IO,
                  4096, timed=False)
    assert n == 0  # the first HELLO waits for the MCU's telemetry
    assert m.call64("mg_calib_stage_us", p, 0) == BASE_US  # the first control tick's base
    assert arm.STOP < program.HEAP_BASE


@pytest.mark.slow
@pytest.mark.parametrize("scenario", program.SCENARIOS["002"])
def test_whole_002_runs_replay_equal_and_within_the_calibrated_band(elf, scenario):
    """A whole shipped 002 run replayed with every quantum equal; the medians of 6 control
    steps and 6 frame pipelines within 0.8-1.25 of their charge (docs/budget.md)."""
    import statistics

    rec = record_steps(scenario)
    ticks, frames = program.pick(rec, 6)
    samples = program.Replay(program.ProgramArm9(elf), rec).run(ticks, frames)
    for kind in ("control", "frame"):
        ratios = [s.modelled_us / (s.timing.cycles / 400) for s in samples if s.kind == kind]
        assert len(ratios) == 6 and 0.8 <= statistics.median(ratios) <= 1.25, (kind, ratios)


@pytest.mark.parametrize("per_method", [
    pytest.param(1, id="one_run_a_method"), pytest.param(2, marks=pytest.mark.slow, id="both")])
def test_calibrate_adds_the_rows_of_each_method_in_the_c_program(tmp_path, elf, monkeypatch,
                                                                  per_method):
    """calibrate with a recorder: the shipped runs of each method the C program has (their
    first 1.2 s here) replayed, one control step and one frame pipeline each, a row per stage
    and method, every quantum equal. The fast suite replays one run a method (~3.5 s of
    emulation each), the second (paper002-marker's replay is the test above's); the slow test
    both. (calibrate's ``scenarios`` selects among a corpus' scenarios: this one has none.)"""
    import json

    from mobigrasp.calib import calibrate, corpus

    monkeypatch.setattr(program, "SCENARIOS",
                        {m: s[-per_method:] for m, s in program.SCENARIOS.items()})
    (tmp_path / corpus.INDEX).write_text(json.dumps(
        {"format": corpus.FORMAT, "scenarios": [], "frames": []}))
    runs = program.scenarios_in_program(elf)
    steps = []
    result = calibrate.calibrate(tmp_path, 1, record=lambda sc: record_steps(
        sc, time_limit_s=1.2), on_step=lambda *a: steps.append(a))
    assert [s[:2] for s in steps] == [(k + 1, len(runs)) for k in range(len(runs))]
    methods = program.methods_in_program(elf)
    assert set(result["stages"]) == {n for m in methods for n in program.stage_names(m)}
    assert len(runs) == per_method * len(methods)
    for name, s in result["stages"].items():
        assert s["result_mismatches"] == 0, name
        assert s["frames"] == per_method and s["emulated_median_us"] > 0, name


def test_the_calibrated_elf_is_the_board_s_with_its_entries_and_armv4t(elf):
    """The ELF replayed is make hostc-arm's with the calibration's entries kept: every symbol
    of the board's ELF at the same name, no instruction newer than ARMv4T."""
    from mobigrasp.calib import armhost

    board = program.Elf.read(armhost.build_elf())
    assert set(board.symbols) <= set(elf.symbols)
    assert set(program.ENTRIES) <= set(elf.symbols) - set(board.symbols)
    assert armhost.not_v4t(armhost.disassemble(armhost.build_elf(program.ENTRIES))) == []
