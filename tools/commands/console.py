"""``mobigrasp console --port PORT``: a small interactive shell to poke an MCU, emulated or real.

Commands: ``hello``, ``servos US US US US US US [SLEW]``, ``servos-mrad MRAD x6 [SLEW]``,
``gripper PERMILLE``, ``wheels LEFT_MMPS RIGHT_MMPS``, ``stop``, ``heartbeat``,
``param get NAME|ID``, ``param set NAME|ID VALUE``, ``params`` (the table), ``telemetry`` (latest
decoded; ``telemetry --watch [N]``: the next N, one field per line), ``stats``, ``quit``. Reliable
commands wait (up to ``--reply-timeout`` wall seconds) for their ACK/NACK and print it, NACK
reasons by name, plus HELLO_ACK / PARAM_VALUE. Lines can come from a pipe: the shell needs no
TTY, which is also how it is tested.

Once HELLO is answered the session is open and a thread sends a HEARTBEAT every
``--heartbeat-ms`` (default 100 ms, under the firmware's 250 ms watchdog), so a ``wheels``
command keeps the wheels turning while the user types; the same thread reads the MCU's telemetry
and says when the watchdog tripped (its flag rose or its trip count grew) and when it cleared.
Bytes the MCU sent before the port was opened leave the first frame cut: what the parser
rejects before the first whole frame is not counted as an error (``stats`` says how many bytes
it skipped). Lines typed are kept in ``~/.mobigrasp_history`` (readline) across sessions.
"""

from __future__ import annotations

import argparse
import cmd
import os
import sys
import threading
import time
from pathlib import Path

from mobigrasp.mcu_sim import checks

HISTORY_FILE = ".mobigrasp_history"  # in the user's home directory
HISTORY_LINES = 1000
HEARTBEAT_MS = 100  # under the firmware's default watchdog_ms (250)
_PARSER_ERRORS = ("crc_errors", "oversize", "unknown_type", "bad_version", "truncated",
                  "cobs_errors", "garbage_bytes")


class ConsoleShell(cmd.Cmd):
    """The shell; ``link`` is a :class:`mobigrasp.link.messages.Link` to the MCU."""

    intro = "mobigrasp console: 'help' lists commands, 'quit' leaves."
    prompt = "mcu> "

    def __init__(self, link, reply_timeout_s: float = 1.0, stdin=None, stdout=None,
                 heartbeat_ms: int = HEARTBEAT_MS) -> None:
        super().__init__(stdin=stdin, stdout=stdout)
        if stdin is not None and not stdin.isatty():
            self.use_rawinput = False
        self.link = link
        self.reply_timeout_s = reply_timeout_s
        self.heartbeat_s = heartbeat_ms / 1000.0  # 0: never
        self.latest_telemetry = None
        self.telemetry_count = 0
        self.port_closed = False
        self.session_open = False  # HELLO answered: heartbeats go out
        self.heartbeats_sent = 0
        self._next_heartbeat_s: float | None = None
        self._watchdog_on = False
        self._watchdog_said = False  # a trip was announced and has not cleared yet
        self._watchdog_trips: int | None = None
        # parser rejections up to the first whole frame: the cut frame of bytes sent before the
        # port was opened (None until a frame arrived)
        self._errors_before_first: dict[str, int] | None = None
        self._inbox: list = []  # received messages other than telemetry, for the command
        self._watched: list | None = None  # telemetry received during `telemetry --watch`
        self._lock = threading.RLock()  # the link is used by the command and the heartbeat
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # -- plumbing ------------------------------------------------------------------------------
    def say(self, text: str) -> None:
        """Print one line to the shell's output."""
        with self._lock:
            self.stdout.write(text + "\n")
            self.stdout.flush()

    def _poll(self) -> list:
        """``link.poll()`` (telemetry absorbed, other messages returned with those the
        heartbeat thread kept); a vanished port is reported once and ends the shell."""
        from mobigrasp.link.base import LinkClosed

        with self._lock:
            if not self.port_closed:
                try:
                    self._inbox.extend(self._absorb(self.link.poll()))
                except LinkClosed as exc:
                    self.port_closed = True
                    self.say(f"port closed: {exc}")
                if self._errors_before_first is None and self.link.rx_frames:
                    st = self.link.stats
                    self._errors_before_first = {k: st.get(f"parser_{k}", 0)
                                                 for k in _PARSER_ERRORS}
            out, self._inbox = self._inbox, []
            return out

    def heartbeat_step(self, now_s: float) -> None:
        """One turn of the heartbeat thread at wall time ``now_s``: send a HEARTBEAT when one is
        due (session open), and read what arrived (telemetry: the watchdog notices)."""
        from mobigrasp.protocol.messages import Heartbeat

        with self._lock:
            if self.port_closed:
                return
            if self.session_open and self.heartbeat_s > 0:
                if self._next_heartbeat_s is None or now_s >= self._next_heartbeat_s:
                    try:
                        self.link.send(Heartbeat(int(now_s * 1e6) & 0xFFFF_FFFF))
                        self.heartbeats_sent += 1
                    except Exception as exc:  # a vanished port ends the shell, quietly here
                        self.port_closed = True
                        self.say(f"port closed: {exc}")
                        return
                    self._next_heartbeat_s = now_s + self.heartbeat_s
            # _poll() swaps in a new inbox: bind extend() to that one, after the call, or the
            # replies read here would go into the old list and be lost to the waiting command
            received = self._poll()
            self._inbox.extend(received)

    def _heartbeat_loop(self) -> None:
        while not self._stop.wait(min(self.heartbeat_s, 0.05) if self.heartbeat_s else 0.05):
            self.heartbeat_step(time.monotonic())

    def _open_session(self) -> None:
        self.session_open = True
        if self._thread is None:
            self._thread = threading.Thread(target=self._heartbeat_loop, daemon=True,
                                            name="console-heartbeat")
            self._thread.start()

    def postloop(self) -> None:
        """Stop the heartbeat thread."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

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
                self._watch_watchdog(r.msg)
                if self._watched is not None:
                    self._watched.append(r.msg)
                self.latest_telemetry = r.msg
                self.telemetry_count += 1
            else:
                rest.append(r.msg)
        return rest

    def _watch_watchdog(self, t) -> None:
        """Say when the MCU's watchdog stop began (flag rose, or the trip count grew between two
        telemetry frames) and when it ended, once the session is open (before HELLO the MCU
        has heard nobody: its watchdog stop then is no news)."""
        from mobigrasp.protocol.messages import FLAG_WATCHDOG

        on = bool(t.flags & FLAG_WATCHDOG)
        grew = self._watchdog_trips is not None and t.watchdog_trips > self._watchdog_trips
        if self.session_open and ((on and not self._watchdog_on) or grew):
            self.say(f"watchdog tripped (t={t.time_us} us, trips={t.watchdog_trips}): no valid "
                     f"frame from the host within watchdog_ms; wheels stopped")
            self._watchdog_said = True
        elif self._watchdog_on and not on and self._watchdog_said:
            self.say(f"watchdog cleared (t={t.time_us} us)")
            self._watchdog_said = False
        self._watchdog_on = on
        self._watchdog_trips = t.watchdog_trips

    def _send(self, msg, wait_for: tuple = ()) -> bool:
        """Send; for reliable messages wait for the ACK/NACK (and ``wait_for`` types) and print.
        True when every reply came (an ACK, not a NACK)."""
        from mobigrasp.mcu_sim.wire_names import nack_reason_name
        from mobigrasp.protocol.messages import Ack, Nack

        try:
            with self._lock:
                seq = self.link.send(msg)
        except Exception as exc:  # a vanished port must not kill the shell
            self.say(f"send failed: {exc}")
            self.port_closed = True
            return False
        if not msg.RELIABLE:
            for m in self._poll():
                self.say(f"received {m}")
            self.say(f"sent {type(msg).__name__} seq={seq}")
            return True
        need_ack, need_more = True, list(wait_for)
        deadline = time.monotonic() + self.reply_timeout_s
        while need_ack or need_more:
            for m in self._poll():
                if isinstance(m, Ack) and m.acked_seq == seq:
                    self.say(f"ACK seq={seq}")
                    need_ack = False
                elif isinstance(m, Nack) and m.acked_seq == seq:
                    self.say(f"NACK seq={seq} reason={nack_reason_name(m.reason)}")
                    return False
                elif any(isinstance(m, t) for t in need_more):
                    self.say(self._describe(m))
                    need_more = [t for t in need_more if not isinstance(m, t)]
                else:
                    self.say(f"received {m}")
            left = deadline - time.monotonic()
            if not need_ack and not need_more:
                return True
            if left <= 0:
                self.say(f"no reply to seq={seq} within {self.reply_timeout_s} s")
                return False
            if self.port_closed:
                return False
            self._wait(min(left, 0.05))
        return True

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

    history = None  # a _History when run as the command: piped lines are added to it

    def precmd(self, line: str) -> str:
        """Accept the dashed spelling ``servos-mrad`` (cmd only allows identifiers)."""
        if self.history is not None:
            self.history.add(line.rstrip("\n"))
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

        if self._send(Hello(PROTOCOL_VERSION, "console", 0), wait_for=(HelloAck,)):
            self._open_session()

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
        """heartbeat: one HEARTBEAT now (after hello they go out every --heartbeat-ms anyway)."""
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

        for pid, name, default, lo, hi, writable, _safety in PARAM_TABLE:
            self.say(f"{pid:4d} {name:<18} default {default:<6} [{lo}, {hi}]"
                     f"{'' if writable else ' read-only'}")

    def _next_telemetry(self, after: int):
        """Wait (up to the reply timeout) until more than ``after`` telemetry frames arrived;
        the latest, or None."""
        self._keep(self._poll())
        deadline = time.monotonic() + self.reply_timeout_s
        while (self.telemetry_count <= after and not self.port_closed
               and time.monotonic() < deadline):
            self._wait(0.05)
            self._keep(self._poll())
        return self.latest_telemetry if self.telemetry_count > after else None

    def _keep(self, msgs: list) -> None:
        with self._lock:  # not for this command: left for the next one that waits for replies
            self._inbox.extend(msgs)

    def do_telemetry(self, arg: str) -> None:
        """telemetry [--watch [N]]: the latest decoded telemetry on one line (flags by name);
        with --watch the next N frames (default 5), one field per line."""
        from mobigrasp.mcu_sim.wire_names import flags_text

        words = arg.split()
        if words and words[0] == "--watch":
            try:
                count = int(words[1]) if len(words) > 1 else 5
                if len(words) > 2 or count < 1:
                    raise ValueError
            except ValueError:
                self.say("usage: telemetry [--watch [N]]  (N >= 1)")
                return
            with self._lock:
                self._watched = []
                first = self.telemetry_count + 1
            try:
                for k in range(count):
                    while len(self._watched) <= k:
                        if self._next_telemetry(self.telemetry_count) is None:
                            self.say("no telemetry received")
                            return
                    self._say_fields(first + k, self._watched[k])
            finally:
                with self._lock:
                    self._watched = None
            return
        if words:
            self.say("usage: telemetry [--watch [N]]")
            return
        t = self.latest_telemetry or self._next_telemetry(0)
        if t is None:
            self.say("no telemetry received yet")
            return
        self.say(f"t={t.time_us} us enc=({t.enc_left}, {t.enc_right}) servo_us={list(t.servo_us)} "
                 f"sonar_mm={list(t.sonar_mm)} flags=0x{t.flags:02x} ({flags_text(t.flags)}) "
                 f"crc_errors={t.crc_errors} overruns={t.overruns} limit_hits={t.limit_hits} "
                 f"watchdog_trips={t.watchdog_trips} ({self.telemetry_count} received)")

    def _say_fields(self, number: int, t) -> None:
        from mobigrasp.mcu_sim.wire_names import flags_text

        self.say(f"telemetry #{number}")
        for name, value in (
                ("time_us", t.time_us), ("enc_left", t.enc_left), ("enc_right", t.enc_right),
                ("servo_us", list(t.servo_us)), ("sonar_mm", list(t.sonar_mm)),
                ("flags", f"0x{t.flags:02x} {flags_text(t.flags)}"),
                ("crc_errors", t.crc_errors), ("overruns", t.overruns),
                ("limit_hits", t.limit_hits), ("watchdog_trips", t.watchdog_trips)):
            self.say(f"  {name:<15} {value}")

    def link_stats(self) -> dict[str, int]:
        """The link's counters, less the parser's rejections before the first whole frame (the
        frame cut by opening the port mid-way), which are in ``skipped_before_first_frame``."""
        with self._lock:
            st = dict(self.link.stats)
            before = self._errors_before_first
        if before is None:  # no whole frame yet: everything so far may be the cut one
            before = {k: st.get(f"parser_{k}", 0) for k in _PARSER_ERRORS}
        for k in _PARSER_ERRORS:
            if f"parser_{k}" in st:
                st[f"parser_{k}"] -= before[k]
        st["skipped_before_first_frame"] = before.get("garbage_bytes", 0)
        return st

    def do_stats(self, arg: str) -> None:
        """stats: link counters on this side (and heartbeats sent)."""
        self._keep(self._poll())
        st = self.link_stats()
        st["heartbeats_sent"] = self.heartbeats_sent
        self.say(" ".join(f"{k}={v}" for k, v in st.items()))

    def do_quit(self, arg: str) -> bool:
        """quit: leave the console."""
        return True

    do_EOF = do_quit


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``console`` subcommand."""
    p = sub.add_parser("console", help="interactive shell to send commands to an MCU on PORT")
    p.add_argument("--port", required=True,
                   help="serial port: /dev/pts/N (the path `mobigrasp mcu` prints), /dev/ttyUSB0")
    p.add_argument("--reply-timeout", type=checks.arg_number(0.0, 3600.0, "s", lo_open=True),
                   default=1.0,
                   help="wall seconds to wait for an ACK (default 1)")
    p.add_argument("--heartbeat-ms", type=_heartbeat_ms, default=HEARTBEAT_MS,
                   help=f"HEARTBEAT period once HELLO is answered (default {HEARTBEAT_MS}; "
                        f"0: none, the MCU's watchdog then stops the wheels)")
    p.set_defaults(func=run)


def _heartbeat_ms(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 60_000:
        raise argparse.ArgumentTypeError(f"must be an integer in [0, 60000] ms, got {text!r}")
    return value


def history_path() -> Path:
    """``~/.mobigrasp_history`` (HOME as the environment says)."""
    return Path(os.path.expanduser("~")) / HISTORY_FILE


class _History:
    """Lines typed, kept across sessions with readline; a missing or unreadable file starts
    an empty history, a file that cannot be written is reported on stderr."""

    def __init__(self, path: Path, piped: bool) -> None:
        try:
            import readline
        except ImportError:  # no readline on this Python: no history
            self.readline = None
            return
        self.readline = readline
        self.path = path
        self.piped = piped  # input() adds typed lines itself; piped lines are added here
        readline.clear_history()
        readline.set_history_length(HISTORY_LINES)
        try:
            readline.read_history_file(str(path))
        except (OSError, UnicodeDecodeError):
            pass

    def add(self, line: str) -> None:
        if self.readline is not None and self.piped and line.strip():
            self.readline.add_history(line)

    def save(self) -> None:
        if self.readline is None:
            return
        try:
            self.readline.write_history_file(str(self.path))
        except OSError as exc:
            print(f"mobigrasp console: cannot write history {self.path}: {exc}",
                  file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    """Open the port and run the shell on stdin/stdout."""
    from mobigrasp.link.messages import Link
    from mobigrasp.link.registry import open_transport

    try:
        transport = open_transport(args.port)
    except (OSError, ValueError) as exc:
        print(f"mobigrasp console: cannot open {args.port}: {exc}", file=sys.stderr)
        return 2
    history = _History(history_path(), piped=not sys.stdin.isatty())
    with Link(transport) as link:
        shell = ConsoleShell(link, args.reply_timeout, stdin=sys.stdin, stdout=sys.stdout,
                             heartbeat_ms=args.heartbeat_ms)
        shell.history = history
        if not sys.stdin.isatty():
            shell.prompt = ""
        try:
            shell.cmdloop()
        finally:
            history.save()
    return 0
