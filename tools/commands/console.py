"""``mobigrasp console --port PORT``: a small interactive shell to poke an MCU, emulated or real.

Commands: ``hello``, ``servos US US US US US US [SLEW]``, ``servos-mrad MRAD x6 [SLEW]``,
``gripper PERMILLE``, ``wheels LEFT_MMPS RIGHT_MMPS``, ``stop``, ``heartbeat``,
``param get NAME|ID``, ``param set NAME|ID VALUE``, ``params`` (the table), ``telemetry`` (latest
decoded), ``stats``, ``quit``. Reliable commands wait (up to ``--reply-timeout`` wall seconds) for
their ACK/NACK and print it, plus HELLO_ACK / PARAM_VALUE. Lines can come from a pipe: the shell
needs no TTY, which is also how it is tested.
"""

from __future__ import annotations

import argparse
import cmd
import sys
import time

NACK_NAMES = {1: "OUT_OF_RANGE", 2: "UNKNOWN_TYPE", 3: "BAD_LENGTH", 4: "NOT_READY",
              5: "BAD_PARAM", 6: "BAD_VERSION"}


class ConsoleShell(cmd.Cmd):
    """The shell; ``link`` is a :class:`mobigrasp.link.messages.Link` to the MCU."""

    intro = "mobigrasp console: 'help' lists commands, 'quit' leaves."
    prompt = "mcu> "

    def __init__(self, link, reply_timeout_s: float = 1.0, stdin=None, stdout=None) -> None:
        super().__init__(stdin=stdin, stdout=stdout)
        if stdin is not None and not stdin.isatty():
            self.use_rawinput = False
        self.link = link
        self.reply_timeout_s = reply_timeout_s
        self.latest_telemetry = None
        self.telemetry_count = 0
        self.port_closed = False

    # -- plumbing ------------------------------------------------------------------------------
    def say(self, text: str) -> None:
        """Print one line to the shell's output."""
        self.stdout.write(text + "\n")

    def _poll(self) -> list:
        """``link.poll()``; a vanished port is reported once and ends the shell."""
        from mobigrasp.link.base import LinkClosed

        if self.port_closed:
            return []
        try:
            return self.link.poll()
        except LinkClosed as exc:
            self.port_closed = True
            self.say(f"port closed: {exc}")
            return []

    def _wait(self, timeout_s: float) -> None:
        try:
            self.link.wait(timeout_s)
        except Exception:  # closed underneath us: the next poll reports it
            self.port_closed = True

    def postcmd(self, stop: bool, line: str) -> bool:
        """Leave when the port went away."""
        return stop or self.port_closed

    def _absorb(self, received) -> list:
        from mobigrasp.protocol.messages import Telemetry

        rest = []
        for r in received:
            if isinstance(r.msg, Telemetry):
                self.latest_telemetry = r.msg
                self.telemetry_count += 1
            else:
                rest.append(r.msg)
        return rest

    def _send(self, msg, wait_for: tuple = ()) -> None:
        """Send; for reliable messages wait for the ACK/NACK (and ``wait_for`` types) and print."""
        from mobigrasp.protocol.messages import Ack, Nack

        try:
            seq = self.link.send(msg)
        except Exception as exc:  # a vanished port must not kill the shell
            self.say(f"send failed: {exc}")
            self.port_closed = True
            return
        if not msg.RELIABLE:
            self._absorb(self._poll())
            self.say(f"sent {type(msg).__name__} seq={seq}")
            return
        need_ack, need_more = True, list(wait_for)
        deadline = time.monotonic() + self.reply_timeout_s
        while need_ack or need_more:
            for m in self._absorb(self._poll()):
                if isinstance(m, Ack) and m.acked_seq == seq:
                    self.say(f"ACK seq={seq}")
                    need_ack = False
                elif isinstance(m, Nack) and m.acked_seq == seq:
                    self.say(f"NACK seq={seq} reason={NACK_NAMES.get(m.reason, m.reason)}")
                    return
                elif any(isinstance(m, t) for t in need_more):
                    self.say(self._describe(m))
                    need_more = [t for t in need_more if not isinstance(m, t)]
                else:
                    self.say(f"received {m}")
            left = deadline - time.monotonic()
            if left <= 0:
                self.say(f"no reply to seq={seq} within {self.reply_timeout_s} s")
                return
            if self.port_closed:
                return
            if need_ack or need_more:
                self._wait(min(left, 0.05))

    @staticmethod
    def _describe(m) -> str:
        from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE
        from mobigrasp.protocol.messages import HelloAck, ParamValue

        if isinstance(m, HelloAck):
            return (f"HELLO_ACK firmware={m.firmware_id} protocol={m.proto_version} "
                    f"capabilities=0x{m.capabilities:04x}")
        if isinstance(m, ParamValue):
            names = {row[0]: row[1] for row in PARAM_TABLE}
            return f"{names.get(m.param_id, m.param_id)} = {m.value}"
        return str(m)

    def _ints(self, arg: str, count: tuple[int, ...]) -> list[int] | None:
        try:
            values = [int(x) for x in arg.split()]
        except ValueError:
            self.say(f"integers expected, got {arg!r}")
            return None
        if len(values) not in count:
            self.say(f"expected {' or '.join(map(str, count))} integers, got {len(values)}")
            return None
        return values

    def _make(self, factory, *values):
        try:
            return factory(*values)
        except ValueError as exc:
            self.say(f"refused: {exc}")
            return None

    def precmd(self, line: str) -> str:
        """Accept the dashed spelling ``servos-mrad`` (cmd only allows identifiers)."""
        if line.startswith("servos-mrad"):
            return "servos_mrad" + line[len("servos-mrad"):]
        return line

    def emptyline(self) -> bool:
        """An empty line does nothing (instead of repeating the last command)."""
        return False

    def default(self, line: str) -> bool:
        """Unknown command."""
        self.say(f"unknown command {line.split()[0]!r}; 'help' lists commands")
        return False

    # -- commands ------------------------------------------------------------------------------
    def do_hello(self, arg: str) -> None:
        """hello: open the session (HELLO -> ACK + HELLO_ACK)."""
        from mobigrasp.protocol.frame import PROTOCOL_VERSION
        from mobigrasp.protocol.messages import Hello, HelloAck

        self._send(Hello(PROTOCOL_VERSION, "console", 0), wait_for=(HelloAck,))

    def _servos(self, arg: str, mode: int) -> None:
        from mobigrasp.protocol.messages import SetServos

        values = self._ints(arg, (6, 7))
        if values is None:
            return
        slew = values[6] if len(values) == 7 else 0
        msg = self._make(SetServos, mode, tuple(values[:6]), slew)
        if msg is not None:
            self._send(msg)

    def do_servos(self, arg: str) -> None:
        """servos US0 .. US5 [SLEW_US_PER_S]: pulse widths 500..2500 µs (ch0 = gripper)."""
        self._servos(arg, 0)

    def do_servos_mrad(self, arg: str) -> None:
        """servos-mrad GRIP_PERMILLE MRAD1 .. MRAD5 [SLEW_MRAD_PER_S]: joint angles."""
        self._servos(arg, 1)

    def do_gripper(self, arg: str) -> None:
        """gripper PERMILLE: 0 = open, 1000 = closed."""
        from mobigrasp.protocol.messages import Gripper

        values = self._ints(arg, (1,))
        msg = values and self._make(Gripper, values[0])
        if msg:
            self._send(msg)

    def do_wheels(self, arg: str) -> None:
        """wheels LEFT_MMPS RIGHT_MMPS: wheel speed targets (streamed, no ACK)."""
        from mobigrasp.protocol.messages import SetWheels

        values = self._ints(arg, (2,))
        msg = values and self._make(SetWheels, values[0], values[1])
        if msg:
            self._send(msg)

    def do_stop(self, arg: str) -> None:
        """stop: wheels off, arm holds."""
        from mobigrasp.protocol.messages import Stop

        self._send(Stop())

    def do_heartbeat(self, arg: str) -> None:
        """heartbeat: keep the MCU watchdog fed."""
        from mobigrasp.protocol.messages import Heartbeat

        self._send(Heartbeat(int(time.monotonic() * 1e6) & 0xFFFF_FFFF))

    def do_param(self, arg: str) -> None:
        """param get NAME|ID  |  param set NAME|ID VALUE"""
        from mobigrasp.mcu_sim.firmware.params import param_id
        from mobigrasp.protocol.messages import ParamGet, ParamSet, ParamValue

        words = arg.split()
        try:
            if len(words) == 2 and words[0] == "get":
                self._send(ParamGet(param_id(words[1])), wait_for=(ParamValue,))
                return
            if len(words) == 3 and words[0] == "set":
                self._send(ParamSet(param_id(words[1]), int(words[2])), wait_for=(ParamValue,))
                return
        except ValueError as exc:
            self.say(f"refused: {exc}")
            return
        self.say("usage: param get NAME|ID  |  param set NAME|ID VALUE")

    def do_params(self, arg: str) -> None:
        """params: the firmware's parameter table (id, name, default, range)."""
        from mobigrasp.mcu_sim.firmware.params import PARAM_TABLE

        for pid, name, default, lo, hi, writable in PARAM_TABLE:
            self.say(f"{pid:4d} {name:<18} default {default:<6} [{lo}, {hi}]"
                     f"{'' if writable else ' read-only'}")

    def do_telemetry(self, arg: str) -> None:
        """telemetry: print the latest decoded telemetry."""
        self._absorb(self._poll())
        if self.latest_telemetry is None:
            deadline = time.monotonic() + self.reply_timeout_s
            while (self.latest_telemetry is None and not self.port_closed
                   and time.monotonic() < deadline):
                self._wait(0.05)
                self._absorb(self._poll())
        t = self.latest_telemetry
        if t is None:
            self.say("no telemetry received yet")
            return
        self.say(f"t={t.time_us} us enc=({t.enc_left}, {t.enc_right}) servo_us={list(t.servo_us)} "
                 f"sonar_mm={list(t.sonar_mm)} flags=0x{t.flags:02x} crc_errors={t.crc_errors} "
                 f"overruns={t.overruns} limit_hits={t.limit_hits} "
                 f"watchdog_trips={t.watchdog_trips} ({self.telemetry_count} received)")

    def do_stats(self, arg: str) -> None:
        """stats: link counters on this side."""
        self._absorb(self._poll())
        self.say(" ".join(f"{k}={v}" for k, v in self.link.stats.items()))

    def do_quit(self, arg: str) -> bool:
        """quit: leave the console."""
        return True

    do_EOF = do_quit


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``console`` subcommand."""
    p = sub.add_parser("console", help="interactive shell to send commands to an MCU on PORT")
    p.add_argument("--port", required=True,
                   help="serial port: /dev/pts/N (the path `mobigrasp mcu` prints), /dev/ttyUSB0")
    p.add_argument("--reply-timeout", type=float, default=1.0,
                   help="wall seconds to wait for an ACK (default 1)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Open the port and run the shell on stdin/stdout."""
    from mobigrasp.link.messages import Link
    from mobigrasp.link.registry import open_transport

    try:
        transport = open_transport(args.port)
    except (OSError, ValueError) as exc:
        print(f"mobigrasp console: cannot open {args.port}: {exc}", file=sys.stderr)
        return 2
    with Link(transport) as link:
        shell = ConsoleShell(link, args.reply_timeout, stdin=sys.stdin, stdout=sys.stdout)
        if not sys.stdin.isatty():
            shell.prompt = ""
        shell.cmdloop()
    return 0
