"""A scenario's robot in this process with the simulated clock in the test's hands.

Built from the SIM half ``mobigrasp run`` uses (mobigrasp.cosim.sim_side.SimSide: the MCU
backend, the world plant with its camera, the fault wrappers and the rig, the run folder) and the
host end ``mobigrasp sim`` uses (mobigrasp.cosim.serve.external_host.ExternalHost: whatever opens
the pty slave). The session loop is mobigrasp.cosim.session.run_session, run in a thread that
halts before every quantum until the test asks for more time: nothing moves between calls, so a
host loop in the test (write, ``advance_ms``, read) sees the same bytes and frames on any machine.

Quanta are 1 ms (strict alternation, no lag): the host's bytes written before ``advance_ms`` reach
the MCU's line at the start of the first quantum, serialised at 115200 baud; the MCU's bytes of the
whole step are written to the pty in one write before ``advance_ms`` returns (docs/firmware.md:
a host's read then has all of them). ``frame()`` is the frame the camera took last (the
scenario's camera rate, 15 fps), as ``sim``'s ``/frame.png`` would serve it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mobigrasp.cosim.serve.external_host import ExternalHost
from mobigrasp.cosim.session import SessionResult, run_session
from mobigrasp.cosim.sim_side import SimSide
from mobigrasp.link.registry import open_transport
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.wire_names import describe, nacks_sent
from mobigrasp.protocol.frame import FrameParser
from mobigrasp.protocol.messages import MessageError, Telemetry, decode_frame
from mobigrasp.services.run_job import resolve_scenario
from mobigrasp.testing.expect import expect


@dataclass(frozen=True)
class RigTiming:
    """The rig's quantum and coupling step for a test-owned clock (integer µs)."""

    quantum_us: int = 1_000
    couple_us: int = 1_000
    host_lag_quanta: int = 0


@dataclass(frozen=True)
class Truth:
    """World ground truth at one simulated time (never sent to the host)."""

    t_us: int
    base: tuple[float, float, float]  # x_m, y_m, heading_rad
    object_m: tuple[float, float, float]  # x, y, z of the object
    held: bool  # the object is attached to the gripper
    joints_rad: tuple[float, ...]


class _DecodingPort:
    """The rig's serial end (the ExternalHost's) that also decodes what the MCU sends."""

    def __init__(self, inner: Any, robot: SteppedRobot) -> None:
        self._inner = inner
        self._robot = robot
        self._parser = FrameParser()

    def write(self, data: bytes) -> None:
        for frame in self._parser.feed(data):
            try:
                self._robot.sent_by_mcu.append((self._robot.now_us, decode_frame(frame)))
            except MessageError:
                continue
        self._inner.write(data)

    def read(self) -> bytes:
        return self._inner.read()

    def wait_readable(self, timeout_s: float) -> bool:
        return self._inner.wait_readable(timeout_s)


class SessionEnded(RuntimeError):
    """The session ended (time limit, crash) before the time asked for."""


class SteppedRobot:
    """``port``, ``advance_ms``, ``frame``, ``telemetry``, ``truth``, ``expect``; ``close()``
    ends the session and writes the run folder ``run_dir`` (summary.json, trace.jsonl)."""

    timing = RigTiming()
    # the session thread answers at once; a safety limit only (nothing asserts on it)
    handoff_timeout_s = 300.0

    def __init__(self, scenario: str, run_dir: Path, seed: int | None = None,
                 mcu: str = "python", time_limit_s: float | None = None) -> None:
        """``scenario``: shipped name or file; ``time_limit_s``: the session's end in simulated
        time (default: the scenario's)."""
        path, sc = resolve_scenario(str(scenario))
        self.scenario = sc.meta.name
        self.seed = sc.meta.seed if seed is None else int(seed)
        self.run_dir = Path(run_dir)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.time_limit_s = float(time_limit_s or sc.meta.time_limit_s)
        self.sent_by_mcu: list[tuple[int, Any]] = []  # (t_us, decoded message) the MCU sent
        self.summary: dict | None = None
        self._frame: Any = None
        self._transport = open_transport("pty://")
        self.port: str = self._transport.slave_path
        self._host = ExternalHost(self._transport, hold_to_host=True)
        self._sim = SimSide(sc, self.seed, self.run_dir, path, "pty (test clock)",
                            getattr(sc, "faults", None) or FaultPlan(), mcu,
                            on_frame=self._on_frame)
        self._session_host = self._sim.wire(self.timing, self._host,
                                            _DecodingPort(self._host.port, self))
        self._rig = self._sim.rig
        self._cond = threading.Condition()
        self._target_us = 0
        self._halted = False
        self._closing = False
        self._result = SessionResult()
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._session, daemon=True,
                                        name=f"stepped-robot-{self.scenario}")
        self._thread.start()
        self._wait_halted()

    # -- the session thread --------------------------------------------------------------------
    def _session(self) -> None:
        plant = self._sim.plant
        try:
            run_session(self._rig, self._session_host, self._sim.trace, result=self._result,
                        time_limit_us=int(self.time_limit_s * 1e6), truth=plant.truth,
                        on_quantum=lambda t: plant.sample_path(), stop=self._gate)
        except BaseException as exc:  # handed to the test thread
            self._error = exc
        finally:
            with self._cond:
                self._halted = True
                self._closing = True
                self._cond.notify_all()

    def _gate(self) -> str | None:
        """run_session's stop(): halt at the target until the test moves it or closes."""
        with self._cond:
            if self._rig.now_us >= self._target_us:
                self._host.release_to_host()  # the step's bytes in one write (ExternalHost)
            while self._rig.now_us >= self._target_us and not self._closing:
                self._halted = True
                self._cond.notify_all()
                self._cond.wait()
            self._halted = False
            return "closed" if self._closing else None

    def _wait_halted(self) -> None:
        with self._cond:
            if not self._cond.wait_for(lambda: self._halted, self.handoff_timeout_s):
                raise TimeoutError(f"the session did not halt in {self.handoff_timeout_s} s")

    def _on_frame(self, seq: int, t_us: int, rgb: Any) -> None:
        self._frame = rgb

    # -- clock ---------------------------------------------------------------------------------
    @property
    def now_us(self) -> int:
        """Simulated time in µs."""
        return self._rig.now_us

    def advance_ms(self, n: int) -> None:
        """Run ``n`` ms of simulated time (the host's bytes written so far go on the line at
        its start); returns once they have run."""
        if not (isinstance(n, int) and n >= 0):
            raise ValueError(f"advance_ms takes an integer >= 0, got {n!r}")
        with self._cond:
            if self._closing:
                raise SessionEnded(self._ended())
            self._target_us = self._rig.now_us + n * 1000
            self._halted = False
            self._cond.notify_all()
        self._wait_halted()
        if self._rig.now_us < self._target_us:
            raise SessionEnded(self._ended())

    def _ended(self) -> str:
        if self._error is not None:
            return f"the session crashed: {type(self._error).__name__}: {self._error}"
        return (f"the session ended ({self._result.reason}) at "
                f"{self._rig.now_us / 1e6:.3f} s simulated (time limit {self.time_limit_s} s)")

    # -- what the robot shows ------------------------------------------------------------------
    def frame(self) -> Any:
        """The camera's latest frame, uint8 H x W x 3 BGR as OpenCV reads one (a copy); None
        before the first ``advance_ms`` (frame 0 is taken at t = 0 by the first quantum)."""
        if self._frame is None:
            return None
        return self._frame[:, :, ::-1].copy()

    def telemetry(self) -> list[Telemetry]:
        """Telemetry the MCU has sent, decoded, oldest first."""
        return [m for _, m in self.sent_by_mcu if isinstance(m, Telemetry)]

    def nacks(self) -> list[tuple[int, str]]:
        """``(acked_seq, reason name)`` of every NACK the MCU sent, oldest first."""
        return nacks_sent(self.sent_by_mcu)

    def truth(self) -> Truth:
        """The world's ground truth now: base pose, object, held, joints."""
        t = self._sim.plant.world.truth()
        b, o = t["base"], t["object"]
        return Truth(t_us=self.now_us, base=(b["x_m"], b["y_m"], b["heading_rad"]),
                     object_m=(o["x_m"], o["y_m"], o["z_m"]), held=bool(t["attached"]),
                     joints_rad=tuple(t["joints_rad"]))

    def seen(self) -> str:
        """What a failed expectation reports: time, last telemetry, truth."""
        tele = self.telemetry()
        last = describe(tele[-1]) if tele else "no telemetry yet"
        return f"t={self.now_us / 1e6:.3f} s; last telemetry: {last}; truth: {self.truth()}"

    def expect(self, predicate, within_ms: int, step_ms: int = 1, between=None) -> int:
        """Advance in ``step_ms`` steps until ``predicate(robot)`` holds (``between()`` before
        each: your host loop's iteration); the ms it took. ExpectationFailed (an
        AssertionError) after ``within_ms`` simulated ms, with :meth:`seen`."""
        return expect(lambda: predicate(self), within_ms, self.advance_ms, self.seen,
                      step_ms, between)

    def close(self) -> dict:
        """End the session, close the pty, write the run folder; the summary."""
        if self.summary is not None:
            return self.summary
        with self._cond:
            self._closing = True
            self._cond.notify_all()
        self._thread.join(self.handoff_timeout_s)
        self._host.close()
        self._sim.summary["status"] = "crashed" if self._error is not None else "finished"
        self._sim.summary["line"] = self._host.stats()  # bytes both ways, drops
        self._sim.finish(self._result, self._session_host.traffic(), self.time_limit_s)
        self.summary = self._sim.summary
        if self._error is not None:
            raise SessionEnded(self._ended()) from self._error
        return self.summary
