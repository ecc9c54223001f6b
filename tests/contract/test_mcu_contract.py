"""One contract for every MCU the rig can drive (mobigrasp.mcu_sim.backend.McuBackend): each
registered backend, the fault wrapper around one, and the test fake the rig tests use."""

import inspect
import math

import pytest
from rig_fakes import FakeMcu

from mobigrasp.mcu_sim.backend import MCU_BACKENDS, McuBackend, UnknownBackend, open_mcu
from mobigrasp.mcu_sim.faults.injectors import RunFaults
from mobigrasp.mcu_sim.faults.plan import FaultPlan
from mobigrasp.mcu_sim.faults.safety import SafetyMonitor
from mobigrasp.mcu_sim.faults.wrappers import FaultedMcu
from mobigrasp.mcu_sim.firmware.params import P_TELEMETRY_HZ
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import FrameParser

KINDS = [f"backend:{name}" for name in sorted(MCU_BACKENDS)] + ["faulted:python", "fake"]


def _make(kind: str):
    if kind.startswith("backend:"):
        return open_mcu(kind.split(":", 1)[1])
    if kind == "faulted:python":
        return FaultedMcu(open_mcu("python"), RunFaults(FaultPlan(), 1), SafetyMonitor(250_000))
    return FakeMcu()


def _members() -> list[str]:
    return [n for n, _ in inspect.getmembers(McuBackend) if not n.startswith("_")]


@pytest.fixture(params=KINDS)
def mcu(request):
    return _make(request.param)


def test_every_method_of_the_interface_is_there(mcu):
    names = _members()
    assert {"advance_outputs", "tx_idle_through_us", "safety_flags", "stats"} <= set(names)
    missing = [n for n in names if not hasattr(mcu, n)]
    assert missing == []


def test_time_moves_only_forward_to_where_it_is_told(mcu):
    assert mcu.now_us == 0
    mcu.advance_to(7_000)
    assert mcu.now_us == 7_000
    pulses, duty = mcu.advance_outputs(12_500)
    assert mcu.now_us == 12_500
    assert pulses == mcu.servo_pulses_us() and len(pulses) == 6
    assert duty == mcu.wheel_duty() and len(duty) == 2
    assert all(-255 <= d <= 255 for d in duty)
    assert [mcu.servo_pulse_us(ch) for ch in range(6)] == list(pulses)


def _hello_frames(mcu) -> list:
    # sent once the firmware has started: the Python models take no time for start-up, the
    # ELF under simavr turns its RX interrupt on about 2.2 ms after reset (docs/firmware.md)
    mcu.uart_rx(m.encode_message(m.Hello(m.PROTOCOL_VERSION, "contract", 0), 0), 20_000)
    mcu.advance_to(80_000)
    chunks = mcu.uart_tx_take()
    times = [t for t, _ in chunks]
    assert times == sorted(times) and all(0 <= t <= 80_000 for t in times)
    assert all(isinstance(d, bytes) for _, d in chunks)
    return [m.decode_frame(f) for f in FrameParser().feed(b"".join(d for _, d in chunks))]


def test_hello_is_answered_and_the_handshake_is_reported(mcu):
    assert mcu.safety_flags()[1] is False
    msgs = _hello_frames(mcu)
    assert any(isinstance(x, m.HelloAck) for x in msgs)
    assert mcu.uart_tx_take() == []  # taken once
    tripped, handshake = mcu.safety_flags()
    assert handshake is True and isinstance(tripped, bool)


def test_idle_line_answer_is_none_or_not_in_the_past(mcu):
    mcu.advance_to(20_000)
    idle = mcu.tx_idle_through_us()
    assert idle is None or idle >= mcu.now_us


def _idle_answers_and_bytes(mcu, frame: bytes, start_us: int, end_us: int, step_us: int = 500):
    """Put ``frame`` on the RX line at ``start_us``, then ask tx_idle_through_us every
    ``step_us`` to ``end_us``: the (time, answer) pairs and the stop-bit time of every byte
    sent meanwhile (the rig takes what left before it asks)."""
    mcu.uart_rx(frame, start_us)
    byte_us = 10e6 / mcu.baud
    answers, stops = [], []
    for t in range(mcu.now_us, end_us + 1, step_us):
        mcu.advance_to(t)
        for last, data in mcu.uart_tx_take():
            stops += [last - (len(data) - 1 - i) * byte_us for i in range(len(data))]
        answers.append((t, mcu.tx_idle_through_us()))
    return answers, stops


def test_no_byte_leaves_before_the_idle_answer(mcu):
    # a HELLO (answered), then telemetry alone, then PARAM_SETs that change nothing (answered by
    # ACK and PARAM_VALUE, on the AVR about 1.8 ms after the frame, one that comes as a
    # telemetry frame has left before the next is due): each answer is checked against the
    # bytes sent until the next frame goes on the line
    hello = m.encode_message(m.Hello(m.PROTOCOL_VERSION, "contract", 0), 0)
    sets = [m.encode_message(m.ParamSet(P_TELEMETRY_HZ, 50), seq) for seq in (1, 2, 3)]
    ahead = 0
    for frame, start, end in ((hello, 20_000, 150_000), (sets[0], 150_000, 200_000),
                              (sets[1], 200_000, 250_000), (sets[2], 260_000, 300_000)):
        answers, stops = _idle_answers_and_bytes(mcu, frame, start, end)
        for t, through in answers:
            if through is None:
                continue
            assert through >= t
            assert all(s > through - 1 for s in stops if s > t), (t, through)
            ahead += through >= t + 5_000
    if mcu.tx_idle_through_us() is not None:  # a backend that can tell does, most of the time
        assert ahead >= 100


def test_inputs_and_counters(mcu):
    calls = []
    mcu.set_sonar_provider(lambda i: calls.append(i) or 1.0)
    mcu.set_encoder_ticks(10, -10, 0)
    mcu.advance_to(100_000)
    stats = mcu.stats()
    assert isinstance(stats, dict) and all(type(v) is int for v in stats.values())
    assert type(mcu.limit_hits()) is int and mcu.limit_hits() >= 0
    assert math.isfinite(mcu.baud) and mcu.baud > 0 and abs(mcu.baud_error_pct) < 5.0


def test_reset_forgets_the_session(mcu):
    _hello_frames(mcu)
    mcu.reset()
    mcu.advance_to(mcu.now_us + 1_000)
    assert mcu.safety_flags()[1] is False


def test_unknown_backend_is_rejected_by_name():
    with pytest.raises(UnknownBackend, match=r"'simavr2'.*known: .*python"):
        open_mcu("simavr2")
