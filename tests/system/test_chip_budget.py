"""Both programs fit their chips in the shipped scenarios: the host misses no control deadline
and drops no frame for lack of time, in process and over the pty; the avr-gcc ELF under simavr
stays within the AVR's budgets (load, interrupts off) and loses no byte (docs/budget.md,
docs/firmware.md "simavr")."""

from __future__ import annotations

import shutil

import pytest

from mobigrasp.mcu_sim.simavr.profile import IRQ_OFF_BUDGET_CYCLES
from mobigrasp.services.run_job import RunOptions, execute, shipped_scenarios

SHIPPED = sorted(p.stem for p in shipped_scenarios())
AVR_LOAD_MAX_PERMILLE = 300  # the bar of the chip budget, under the profile's 500

needs_avr = pytest.mark.skipif(shutil.which("avr-gcc") is None,
                               reason="avr-gcc is missing (make firmware installs it)")


def _run(name: str, tmp_path, **kw) -> dict:
    summary, _ = execute(RunOptions(scenario=name, out=tmp_path / name, progress=False,
                                    plots=False, **kw))
    return summary


def _host_fits(summary: dict) -> None:
    budget = summary["budget"]
    assert budget["deadline_misses"] == 0, budget
    assert budget["frames_dropped_busy"] == 0, budget
    assert budget["fits"], budget["verdict"]


def _avr_fits(summary: dict) -> None:
    mcu = summary["mcu"]
    figures = {k: mcu[k] for k in ("avr_load_permille", "avr_irq_off_max_cycles", "overruns",
                                   "rx_ring_overruns", "avr_rx_line_lost", "rx_line_dropped",
                                   "corrupt_frames", "tx_dropped")}
    assert 0 < figures["avr_load_permille"] <= AVR_LOAD_MAX_PERMILLE, figures
    assert 0 < figures["avr_irq_off_max_cycles"] <= IRQ_OFF_BUDGET_CYCLES, figures
    assert all(figures[k] == 0 for k in ("overruns", "rx_ring_overruns", "avr_rx_line_lost",
                                         "rx_line_dropped", "corrupt_frames", "tx_dropped")), \
        figures
    assert summary["protocol"]["crc_errors"] == 0 and summary["protocol"]["retransmits"] == 0


@pytest.mark.slow
@pytest.mark.timeout(900)
@pytest.mark.parametrize("name", SHIPPED)
def test_the_host_keeps_its_deadlines_in_process_and_over_the_pty(name, tmp_path):
    inproc = _run(name, tmp_path / "inproc", transport="inproc")
    pty = _run(name, tmp_path / "pty", transport="pty")
    for summary in (inproc, pty):
        assert summary["success"], summary["end_reason"]
        _host_fits(summary)
    assert pty["trace_sha256"] == inproc["trace_sha256"]


@needs_avr
@pytest.mark.slow
@pytest.mark.timeout(900)
@pytest.mark.parametrize("name", SHIPPED)
def test_the_elf_under_simavr_keeps_the_avr_budget(name, tmp_path):
    summary = _run(name, tmp_path, transport="inproc", mcu="simavr")
    assert summary["success"], summary["end_reason"]
    _avr_fits(summary)
    _host_fits(summary)


@needs_avr
def test_the_first_seconds_under_simavr_keep_the_avr_budget(tmp_path):
    # the fast slice: the start-up, the session's opening and the first moves
    summary = _run("paper000-exp1", tmp_path, transport="inproc", mcu="simavr",
                   time_limit_s=3.0)
    assert summary["end_reason"] == "time_limit"
    _avr_fits(summary)
