"""Progress display: a bar on a terminal, whole lines in a pipe; logging levels of -v/-q."""

import io
import logging

from mobigrasp.tools.progress import Progress, RunProgress, log_level, setup_logging


class Clock:
    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


class Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_plain_lines_at_the_interval_when_not_a_terminal():
    clock, buf = Clock(), io.StringIO()
    p = Progress(total=10, desc="campaign", unit="runs", stream=buf, interval_s=5.0,
                 clock=clock)
    assert not p.bar
    for k in range(1, 11):
        clock.t = 2.0 * k  # one item every 2 s: a line every 5 s at most
        p.update(k, f"{k} ok")
    p.close()
    lines = buf.getvalue().splitlines()
    assert "\r" not in buf.getvalue()
    assert 3 <= len(lines) <= 5 and p.lines == len(lines)
    assert lines[-1] == "campaign: 10/10 runs  10 ok"


def test_a_terminal_gets_a_tqdm_bar_with_carriage_returns():
    buf = Tty()
    with Progress(total=4, desc="campaign", unit="runs", stream=buf) as p:
        assert p.bar
        for k in range(1, 5):
            p.update(k, "fine")
    text = buf.getvalue()
    assert "\r" in text and "4/4" in text and "campaign" in text


def test_disabled_prints_nothing():
    buf = Tty()
    p = Progress(total=3, stream=buf, enabled=False)
    p.update(3)
    p.close()
    assert buf.getvalue() == ""


def test_run_progress_reports_simulated_time_state_and_rate():
    clock, buf = Clock(), io.StringIO()
    run = RunProgress(stream=buf, clock=clock, interval_s=1.0)
    for k in range(1, 4):
        clock.t = float(k)
        run(k * 5_000_000, "APPROACH", float(k))
    run.close()
    last = buf.getvalue().splitlines()[-1]
    assert last == "run: 15 s simulated  state=APPROACH rtf=5.0x"


def test_run_progress_finishes_where_the_summary_ends():
    clock, buf = Clock(), io.StringIO()
    run = RunProgress(stream=buf, clock=clock)
    run(1_000_000, "SEARCH", 0.1)
    run.finish({"sim_time_s": 17.1, "task_state": "DONE", "wall_time_s": 1.0})
    assert buf.getvalue() == "run: 17.1 s simulated  state=DONE rtf=17.1x\n"


def test_nothing_is_drawn_before_the_first_update():
    buf = Tty()
    Progress(total=3, stream=buf).close()
    assert buf.getvalue() == ""


def test_log_levels_of_the_flags():
    assert log_level(0, False) == logging.WARNING
    assert log_level(1, False) == logging.INFO
    assert log_level(2, False) == logging.DEBUG
    assert log_level(2, True) == logging.ERROR


def test_setup_logging_routes_the_mobigrasp_logger():
    buf = io.StringIO()
    setup_logging(verbose=1, stream=buf)
    logging.getLogger("mobigrasp.tools.x").info("hello %d", 3)
    logging.getLogger("mobigrasp.tools.x").debug("hidden")
    setup_logging(quiet=True, stream=buf)  # replaces the handler: no duplicate lines
    logging.getLogger("mobigrasp.tools.x").warning("dropped when quiet")
    logging.getLogger("mobigrasp.tools.x").error("kept")
    assert buf.getvalue().splitlines() == ["INFO mobigrasp.tools.x: hello 3",
                                           "ERROR mobigrasp.tools.x: kept"]
    setup_logging()


def test_plain_interval_from_the_environment(monkeypatch):
    from mobigrasp.tools.progress import INTERVAL_ENV, PLAIN_INTERVAL_S, plain_interval_s

    monkeypatch.delenv(INTERVAL_ENV, raising=False)
    assert plain_interval_s() == PLAIN_INTERVAL_S
    monkeypatch.setenv(INTERVAL_ENV, "0")
    assert plain_interval_s() == 0.0
    for bad in ("nan", "-1", "fast", "1e9"):
        monkeypatch.setenv(INTERVAL_ENV, bad)
        assert plain_interval_s() == PLAIN_INTERVAL_S
