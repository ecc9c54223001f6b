"""pytest plugin (``pytest11`` entry point) exposing the emulated MCU to host-program tests.

Fixtures:

- ``emulated_mcu``: an :class:`EmulatedMcu` with the default configuration, on a new pty.
- ``emulated_mcu_factory``: ``make(config=McuConfig(...), wheels="bench"|"still")`` for other
  UART divisors, PARAMs or wheel plants.

The test owns the simulated clock: nothing moves until it calls ``advance_ms`` / ``advance_us``.
A host program under test opens ``emulated_mcu.port`` like a serial device; call
``wait_from_host()`` after it wrote and before advancing time when the exact arrival time
matters: it puts everything written so far on the MCU's RX line (no byte counting). Without a
world the encoders follow ``wheels``: ``bench`` (default), two unloaded motors with their lag,
so a SetWheels turns them; ``still``, always 0. For quick tests the fixture also has its own
host end: ``send(msg)`` writes a message on the slave and waits until the MCU side has it,
``receive(n)`` returns what the host side read back. ``nacks()`` lists the NACKs the MCU sent
with their reasons by name; ``describe(msg)`` prints any message that way.

- ``emulated_robot``: ``robot = emulated_robot("paper000-exp1", speed=1.0)`` serves the
  scenario's robot for the test as ``mobigrasp sim`` does, with the same services, in a thread
  of the test's process (testing/served_robot.py; its clock starting at your host's first
  frame, as ``sim --wait-host``): the scenario's MCU and world in wall time, ``robot.port`` the
  serial pty, ``robot.camera_url`` the MJPEG stream. Run your host program against them; once it
  has closed the port, ``robot.summary`` is the run's summary (``grasped``, ``contacts``,
  ``safety``...), read from the run folder ``robot.run_dir``, and ``robot.exit_code`` what
  ``sim`` would exit with. A session still running after the test body is ended (``stop()``,
  as SIGTERM ends ``sim``) and its folder written all the same.
  ``emulated_robot(scenario, clock="test")`` is the same robot in this process with the clock
  in the test's hands (testing/stepped_robot.py): ``.port``, ``.advance_ms(n)``,
  ``.frame()``, ``.telemetry()``, ``.truth()``, ``.expect(predicate, within_ms)``.
- ``host_program``: the host program ``pytest --robot-host python|c|arm`` names (default
  python), to start against an ``emulated_robot``: ``.robot_kw`` (the robot's options it
  needs: the raw-frame endpoint for the C programs) and ``.argv(robot, method)``.
- ``pytest --robot-port /dev/ttyUSB0 --robot-camera 0``: every ``emulated_robot`` is the real
  robot on that device and camera (testing/bench_robot.py); truth and clock calls
  skip the test with the reason.

This module must stay cheap to import and must never break a pytest run: everything heavy is
imported inside the fixtures.
"""

from __future__ import annotations

import pytest

_PTY_CHUNK = 1024  # well below any pty buffer, so a host-side write never blocks


class EmulatedMcu:
    """A :class:`mcu_sim.mcu_pty.PtyMcu` plus a host-side Link on its slave for convenience."""

    def __init__(self, config=None, wheels: str = "bench", mcu: str = "python") -> None:
        from mobigrasp.mcu_sim.mcu_pty import PtyMcu

        self._pty = PtyMcu(config, wheels=wheels, mcu=mcu)
        self.mcu = self._pty.mcu
        self.port: str = self._pty.port
        self._link = None

    # -- clock ---------------------------------------------------------------------------------
    @property
    def now_us(self) -> int:
        """Simulated time in µs."""
        return self._pty.now_us

    def advance_us(self, n: int) -> None:
        """Pump pty bytes into the UART and run ``n`` µs of simulated time."""
        self._pty.advance_us(n)

    def advance_ms(self, n: int) -> None:
        """Pump pty bytes into the UART and run ``n`` ms of simulated time."""
        self._pty.advance_us(int(n) * 1000)

    def wait_from_host(self, n_bytes: int | None = None, timeout_s: float = 10.0) -> bool:
        """Put every byte a host has written to the port so far on the MCU's RX line, at the
        current simulated time (which does not move); False if the host closed the port.
        With ``n_bytes``: wait (wall clock, up to ``timeout_s``) until the MCU side has read
        that many bytes in all."""
        return self._pty.wait_from_host(n_bytes, timeout_s)

    @property
    def bytes_from_host(self) -> int:
        """Bytes the MCU side has read from the port so far."""
        return self._pty.bytes_from_host

    # -- outputs -------------------------------------------------------------------------------
    def servo_pulses_us(self) -> tuple[int, ...]:
        """Latest measured pulse width of each of the six channels, in whole µs (the timer
        measures them in 0.5 µs steps: rounded half to even); 0 before the first pulse."""
        return tuple(round(self.mcu.servo_pulse_us(ch)) for ch in range(6))

    def wheel_duty(self) -> tuple[int, int]:
        """Signed wheel duties (left, right), -255..255."""
        return self.mcu.wheel_duty()

    def telemetry(self) -> list:
        """Telemetry messages the MCU has sent, decoded, oldest first."""
        return self._pty.telemetry()

    def sent(self) -> list[tuple[int, object]]:
        """Every message the MCU has sent: ``(t_us, message)``."""
        return list(self._pty.sent)

    def nacks(self) -> list[tuple[int, str]]:
        """``(acked_seq, reason)`` of every NACK the MCU sent, the reason by name
        (``"NOT_READY"``), oldest first."""
        return self._pty.nacks()

    @staticmethod
    def describe(msg) -> str:
        """One line for a message, NACK reasons and telemetry flags by name."""
        from mobigrasp.mcu_sim.wire_names import describe

        return describe(msg)

    @property
    def stats(self) -> dict[str, int]:
        """Firmware and UART counters."""
        return self.mcu.stats()

    # -- built-in host end ---------------------------------------------------------------------
    def host_link(self):
        """A :class:`mobigrasp.link.messages.Link` on the slave (opened on first use)."""
        if self._link is None:
            from mobigrasp.link.messages import Link
            from mobigrasp.link.registry import open_transport

            self._link = Link(open_transport(self.port))
        return self._link

    def send(self, msg, seq: int | None = None, timeout_s: float = 10.0) -> int:
        """Send ``msg`` from the host end; returns its seq once the MCU side has the bytes."""
        link = self.host_link()
        if seq is None:
            seq = link.send(msg)
        else:
            link.send_with_seq(msg, seq)
        if not self.wait_from_host(self._host_written(), timeout_s):
            raise TimeoutError(f"the MCU side did not receive the host's bytes in {timeout_s} s")
        return seq

    def send_raw(self, data: bytes, timeout_s: float = 10.0) -> None:
        """Write raw bytes (garbage, floods) from the host end and wait until they arrived.
        Written in pieces the pty buffer can hold; simulated time does not move meanwhile, so
        to the MCU it is one burst at the current time."""
        data = bytes(data)
        for i in range(0, len(data), _PTY_CHUNK):
            self.host_link().send_wire(data[i:i + _PTY_CHUNK])
            if not self.wait_from_host(self._host_written(), timeout_s):
                raise TimeoutError(
                    f"the MCU side did not receive the host's bytes in {timeout_s} s")

    def _host_written(self) -> int:
        return self.host_link().tx_bytes

    def receive(self, count: int = 1, timeout_s: float = 10.0) -> list:
        """Messages the host end has received: waits until at least ``count`` or the timeout."""
        link = self.host_link()
        out = [r.msg for r in link.poll()]
        while len(out) < count:
            if not link.wait(timeout_s):
                break
            out.extend(r.msg for r in link.poll())
        return out

    def close(self) -> None:
        """Close both ends."""
        if self._link is not None:
            self._link.close()
        self._pty.close()


@pytest.fixture
def emulated_mcu_factory():
    """``make(config=None, wheels="bench", mcu="python") -> EmulatedMcu``; ``mcu="native"``
    runs the C firmware; everything made is closed after the test."""
    made: list[EmulatedMcu] = []

    def make(config=None, wheels: str = "bench", mcu: str = "python") -> EmulatedMcu:
        emu = EmulatedMcu(config, wheels, mcu)
        made.append(emu)
        return emu

    yield make
    for emu in made:
        emu.close()


@pytest.fixture
def emulated_mcu(emulated_mcu_factory) -> EmulatedMcu:
    """An emulated ATmega128 on a new pty, default configuration, clock at 0."""
    return emulated_mcu_factory()


def pytest_addoption(parser) -> None:
    """``--robot-port`` and ``--robot-camera``: ``emulated_robot`` on a real robot."""
    group = parser.getgroup("mobigrasp", "mobigrasp robot")
    group.addoption("--robot-port", default=None, metavar="DEVICE",
                    help="emulated_robot is the real robot on this serial device (its truth "
                         "and clock calls skip)")
    group.addoption("--robot-camera", default=None, metavar="INDEX|FILE",
                    help="with --robot-port: the robot's camera for OpenCV (an index, a video "
                         "file, an image sequence such as shots/%%03d.png, a URL)")
    group.addoption("--robot-host", default="python", choices=("python", "c", "arm"),
                    help="the host program the host_program fixture starts: python (mobigrasp "
                         "host, default), c (hostc/ built for this machine) or arm (its ARMv4T "
                         "ELF under qemu-arm -cpu ti925t)")


CLOCKS = ("wall", "test")


@pytest.fixture
def host_program(request):
    """The host program of ``--robot-host`` (testing/host_program.py): ``.robot_kw`` for
    ``emulated_robot(scenario, **robot_kw)``, ``.argv(robot, method)`` its command line."""
    from mobigrasp.testing.host_program import HostProgram

    program = HostProgram(request.config.getoption("robot_host"))
    yield program
    program.close()


@pytest.fixture
def emulated_robot(request, tmp_path):
    """``make(scenario, speed=1.0, clock="wall") -> robot``; every robot made is ended after
    the test (its run folder under the test's tmp_path).

    ``clock="wall"``: a :class:`mobigrasp.testing.served_robot.ServedRobot` (``mobigrasp
    sim``'s session in wall time); ``clock="test"``: a
    :class:`mobigrasp.testing.stepped_robot.SteppedRobot` (in process, simulated time moves
    only in ``advance_ms``/``expect``). With ``--robot-port`` every robot is a
    :class:`mobigrasp.testing.bench_robot.BenchRobot` on that device instead."""
    made: list = []
    bench_port = request.config.getoption("robot_port")

    def make(scenario: str, speed: float = 1.0, clock: str = "wall", **kw):
        """``kw``: ``seed``, ``mcu``, ``time_limit_s`` (both clocks); with the wall clock
        also ``plots`` (default True), ``faults`` (``KEY=VALUE`` strings, as ``sim
        --fault``) and ``raw_frames`` (a socket path, as ``sim --raw-frames``)."""
        if clock not in CLOCKS:
            raise ValueError(f"clock must be one of {', '.join(CLOCKS)}, got {clock!r}")
        if bench_port:
            from mobigrasp.testing.bench_robot import BenchRobot, camera_source

            robot = BenchRobot(scenario, bench_port,
                               camera_source(request.config.getoption("robot_camera")))
        elif clock == "test":
            from mobigrasp.testing.stepped_robot import SteppedRobot

            robot = SteppedRobot(scenario, tmp_path / f"robot-{len(made)}", **kw)
        else:
            from mobigrasp.testing.served_robot import ServedRobot

            robot = ServedRobot(scenario, tmp_path / f"sim-{len(made)}", speed, **kw)
        made.append(robot)
        return robot

    yield make
    for robot in made:
        robot.close()
