"""A scenario's robot served in wall time to the host program under test, as ``mobigrasp sim``
serves it: the pytest plugin's ``emulated_robot(scenario)`` (the wall clock).

The session is mobigrasp.services.sim_job's, the one ``mobigrasp sim`` runs (the SIM side of
cosim/sim_side.py ``SimSide``, an external host on a new pty, the camera's MJPEG server), run in
a thread of the test's process; its clock starts at the host's first valid frame (``sim
--wait-host``). The thread answers nothing itself: the test's host program talks to ``port``
and ``camera_url`` as to ``mobigrasp sim``'s.
"""

from __future__ import annotations

import threading
from pathlib import Path


class RobotDidNotStart(RuntimeError):
    """The session refused its options or did not serve its port in time."""


class ServedRobot:
    """``port`` (the serial pty), ``camera_url`` (the MJPEG stream), ``summary`` once the session
    has ended (the host closed the port, the time limit, :meth:`stop`), ``run_dir``."""

    start_timeout_s = 120.0  # safety limits only: nothing asserts on them
    end_timeout_s = 120.0

    def __init__(self, scenario: str, run_dir: Path, speed: float = 1.0, plots: bool = True,
                 seed: int | None = None, mcu: str = "python",
                 time_limit_s: float | None = None, faults: tuple[str, ...] = (),
                 raw_frames: Path | None = None) -> None:
        """``plots``: write plots/ and report.html (a few seconds at the end); ``seed``,
        ``mcu``, ``time_limit_s``, ``faults`` (``KEY=VALUE`` strings) and ``raw_frames`` (the
        raw-frame endpoint's socket path) as ``mobigrasp sim``'s options of those names."""
        from mobigrasp.cosim.serve.session import SimOptions

        self.scenario = str(scenario)
        self.run_dir = Path(run_dir)
        self.run_dir.parent.mkdir(parents=True, exist_ok=True)
        self.port = ""
        self.camera_url = ""
        self.exit_code: int | None = None  # mobigrasp sim's: 0 grasped, 1 not (once ended)
        self._opts = SimOptions(scenario=self.scenario, speed=speed, mcu=mcu, wait_host=True,
                                out=self.run_dir, seed=seed, time_limit_s=time_limit_s,
                                raw_frames=raw_frames)
        self._faults, self._plots = tuple(faults), plots
        self._ready = threading.Event()
        self._stop: str | None = None
        self._summary: dict | None = None
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._session, daemon=True,
                                         name=f"served-robot-{self.scenario}")
        self._thread.start()
        self._ready.wait(self.start_timeout_s)
        if self._error is not None or not self.port:
            self.close(raising=False)
            raise RobotDidNotStart(f"mobigrasp sim {self.scenario} did not start: "
                                   f"{self._why()}")

    def _session(self) -> None:
        from mobigrasp.services.sim_job import exit_code, serve_scenario

        try:
            self._summary = serve_scenario(self._opts, self._on_ready,
                                           stop=lambda: self._stop, faults=self._faults,
                                           plots=self._plots)
            self.exit_code = exit_code(self._summary)
        except BaseException as exc:  # handed to the test's thread
            self._error = exc
        finally:
            self._ready.set()

    def _on_ready(self, serial: str, camera: str, serial_tcp: str | None) -> None:
        self.port, self.camera_url = serial, camera
        self._ready.set()

    def _why(self) -> str:
        if self._error is not None:
            return f"{type(self._error).__name__}: {self._error}"
        return f"no serial port in {self.start_timeout_s} s"

    def stop(self) -> None:
        """End the session now (as SIGTERM ends ``mobigrasp sim``); the run folder is written."""
        if self._stop is None:
            self._stop = "terminated"

    def wait(self, timeout_s: float | None = None) -> int | None:
        """Wait for the session to end (the host closed the port, the time limit, stop()); the
        exit code ``mobigrasp sim`` would give. TimeoutError (after stopping it) when it did
        not end in time."""
        self._thread.join(self.end_timeout_s if timeout_s is None else timeout_s)
        if self._thread.is_alive():
            self.stop()
            raise TimeoutError(f"mobigrasp sim {self.scenario} still ran after "
                               f"{self.end_timeout_s if timeout_s is None else timeout_s} s: "
                               f"stopped")
        return self.exit_code

    @property
    def summary(self) -> dict:
        """The run's summary.json, read from ``run_dir`` once the session has ended (waits for
        it)."""
        import json

        self.wait()
        path = self.run_dir / "summary.json"
        if self._summary is None or not path.exists():
            raise RuntimeError(f"mobigrasp sim {self.scenario} wrote no {path}: {self._why()}")
        return json.loads(path.read_text())

    def close(self, raising: bool = True) -> None:
        """Stop the session if it still runs and wait for its run folder."""
        self.stop()
        try:
            self.wait()
        except TimeoutError:
            if raising:
                raise
