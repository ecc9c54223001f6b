"""pytest plugin (``pytest11`` entry point) serving a whole simulated robot to host-program tests.

- ``emulated_robot``: ``robot = emulated_robot("paper000-exp1", speed=1.0)`` serves the scenario
  for the test (services/sim.py, in a child process, as ``mobigrasp sim`` does): its MCU and world
  in wall time, ``robot.port`` the serial pty, ``robot.camera_url`` the MJPEG stream. Run your
  host program against them; once it has closed the port, ``robot.summary`` is the run's summary
  (``grasped``, ``collisions``, ``safety``...), read from the run folder ``robot.run_dir``. A
  session still running after the test body is ended (SIGTERM) and its folder written all the
  same.

The MCU alone with the test's own clock is ``emulated_mcu`` (mobigrasp.mcu_sim.pytest_plugin).
This module must stay cheap to import and must never break a pytest run: everything heavy is
imported inside the fixture's session.
"""

from __future__ import annotations

import pytest


class EmulatedRobot:
    """One served session of a scenario (see the module docstring)."""

    start_timeout_s = 120.0  # safety limits only: nothing asserts on them
    end_timeout_s = 120.0

    def __init__(self, scenario: str, run_dir, speed: float = 1.0, plots: bool = True,
                 seed: int | None = None, time_limit_s: float | None = None,
                 mcu: str = "python") -> None:
        """``plots``: write plots/ and report.html (a few seconds at the end); ``seed``,
        ``time_limit_s``, ``mcu``: as ``mobigrasp sim``'s options."""
        import multiprocessing
        from pathlib import Path

        from mobigrasp.services.sim import serve_in_child

        self.scenario = scenario
        self.run_dir = Path(run_dir)
        self.run_dir.parent.mkdir(parents=True, exist_ok=True)
        self._stderr_path = self.run_dir.parent / f"{self.run_dir.name}.stderr.txt"
        self._stderr_path.write_text("")
        options = {"scenario": str(scenario), "speed": float(speed), "mcu": mcu,
                   "camera_port": 0, "out": self.run_dir, "seed": seed,
                   "time_limit_s": time_limit_s, "plots": plots}
        # spawn: a fresh interpreter, not a copy of this one with its threads
        ctx = multiprocessing.get_context("spawn")
        self._conn, child_end = ctx.Pipe(duplex=False)
        self.proc = ctx.Process(target=serve_in_child, name=f"sim-{scenario}",
                                args=(child_end, options, str(self._stderr_path)))
        self.proc.start()
        child_end.close()
        self._summary: dict | None = None
        self.port, self.camera_url = self._ready()

    def _ready(self) -> tuple[str, str]:
        message: tuple = ("no answer",)
        try:
            if self._conn.poll(self.start_timeout_s):
                message = self._conn.recv()
        except EOFError:
            message = ("ended",)
        if message[0] != "ready":
            self.close()
            raise RuntimeError(f"the session of {self.scenario} did not start ({message}): "
                               f"{self.stderr()}")
        return message[1], message[2]

    def stderr(self) -> str:
        """What the session printed on stderr so far."""
        return self._stderr_path.read_text(errors="replace")

    @property
    def returncode(self) -> int | None:
        """0 grasped, 1 not, 2 bad input; None while the session runs."""
        return self.proc.exitcode

    def stop(self) -> None:
        """End the session now (SIGTERM); the run folder is written."""
        if self.proc.is_alive():
            self.proc.terminate()

    def wait(self, timeout_s: float | None = None) -> int:
        """Wait for the session to end (the host closed the port, the time limit, stop())."""
        self.proc.join(self.end_timeout_s if timeout_s is None else timeout_s)
        if self.proc.exitcode is None:
            self.proc.kill()
            self.proc.join()
            raise TimeoutError(f"the session of {self.scenario} did not end")
        return self.proc.exitcode

    @property
    def summary(self) -> dict:
        """The run's summary.json, once the session has ended (waits for it)."""
        import json

        if self._summary is None:
            self.wait()
            path = self.run_dir / "summary.json"
            if not path.exists():
                raise RuntimeError(f"the session wrote no {path}: {self.stderr()}")
            self._summary = json.loads(path.read_text())
        return self._summary

    def close(self) -> None:
        """Stop the session if it still runs and reap the process."""
        self.stop()
        try:
            self.wait()
        finally:
            self._conn.close()


@pytest.fixture
def emulated_robot(tmp_path):
    """``make(scenario, speed=1.0) -> EmulatedRobot``: a served session for this test; every
    session made is ended after the test (its run folder under the test's tmp_path)."""
    made: list[EmulatedRobot] = []

    def make(scenario: str, speed: float = 1.0, **kw) -> EmulatedRobot:
        """``kw``: ``plots`` (default True), ``seed``, ``time_limit_s``, ``mcu``."""
        robot = EmulatedRobot(scenario, tmp_path / f"sim-{len(made)}", speed, **kw)
        made.append(robot)
        return robot

    yield make
    for robot in made:
        robot.close()
