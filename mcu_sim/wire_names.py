"""Names for what crosses the serial line, for people reading it: NACK reasons, telemetry flags.

The codes themselves are the protocol's (protocol/messages.py, docs/protocol.md); this module only
turns them into the words the tools print (``mobigrasp mcu --log``, ``mobigrasp console``, the
``emulated_mcu`` fixture), so every tool spells a reason and a flag the same way.
"""

from __future__ import annotations

from mobigrasp.protocol import messages as m

NACK_REASONS: dict[int, str] = {
    m.NACK_OUT_OF_RANGE: "OUT_OF_RANGE", m.NACK_UNKNOWN_TYPE: "UNKNOWN_TYPE",
    m.NACK_BAD_LENGTH: "BAD_LENGTH", m.NACK_NOT_READY: "NOT_READY",
    m.NACK_BAD_PARAM: "BAD_PARAM", m.NACK_BAD_VERSION: "BAD_VERSION",
    m.NACK_SEQ_REUSED: "SEQ_REUSED",
}

# Telemetry.flags bits, lowest first
FLAG_NAMES: tuple[tuple[int, str], ...] = (
    (m.FLAG_WATCHDOG, "WATCHDOG"), (m.FLAG_LIMIT, "LIMIT"), (m.FLAG_HANDSHAKE, "HANDSHAKE"),
    (m.FLAG_STOPPED, "STOPPED"), (m.FLAG_RESET, "RESET"),
    (m.FLAG_GRIPPER_CLOSED, "GRIPPER_CLOSED"),
)


def nack_reason_name(code: int) -> str:
    """``BAD_VERSION`` for 6; an unknown code as ``reason_N``."""
    return NACK_REASONS.get(code, f"reason_{code}")


def nacks_sent(sent) -> list[tuple[int, str]]:
    """``(acked_seq, reason name)`` of every NACK in ``sent`` (``(t_us, message)`` pairs)."""
    return [(msg.acked_seq, nack_reason_name(msg.reason)) for _, msg in sent
            if isinstance(msg, m.Nack)]


def flag_names(flags: int) -> list[str]:
    """The names of the bits set in ``flags`` (unknown bits as ``bit_N``), lowest first."""
    names = [name for bit, name in FLAG_NAMES if flags & bit]
    known = 0
    for bit, _ in FLAG_NAMES:
        known |= bit
    rest = flags & ~known
    names += [f"bit_{i}" for i in range(rest.bit_length()) if rest >> i & 1]
    return names


def flags_text(flags: int) -> str:
    """``HANDSHAKE|GRIPPER_CLOSED``, or ``-`` with no flag set."""
    return "|".join(flag_names(flags)) or "-"


def describe(msg: object) -> str:
    """One line for a decoded message; NACK reasons and telemetry flags by name."""
    if isinstance(msg, m.Nack):
        return f"NACK seq={msg.acked_seq} reason={nack_reason_name(msg.reason)}"
    if isinstance(msg, m.Ack):
        return f"ACK seq={msg.acked_seq}"
    if isinstance(msg, m.Telemetry):
        return (f"TELEMETRY t={msg.time_us} us enc=({msg.enc_left}, {msg.enc_right}) "
                f"servo_us={list(msg.servo_us)} sonar_mm={list(msg.sonar_mm)} "
                f"flags={flags_text(msg.flags)} crc_errors={msg.crc_errors} "
                f"overruns={msg.overruns} limit_hits={msg.limit_hits} "
                f"watchdog_trips={msg.watchdog_trips}")
    return repr(msg)
