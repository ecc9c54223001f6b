"""Safety under faults without the rig: the real Mcu, protocol objects, a host stand-in.

Required behaviour tested here: under bit errors on both directions of the line the firmware
never executes a corrupted command nor one twice, and every reliable command arrives eventually
by retransmission; host silence stops the wheels within watchdog period + 50 ms of simulated
time and holds the arm; an MCU reset shows FLAG_RESET, refuses commands until a new handshake,
and works again after it. The injectors are mcu_sim/faults; all time is simulated.
"""

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.mcu_sim.bench_plant import WheelsInTheAir
from mobigrasp.mcu_sim.faults import FaultPlan, RunFaults
from mobigrasp.mcu_sim.firmware import dispatch
from mobigrasp.mcu_sim.firmware.params import param_id
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import PROTOCOL_VERSION, FrameParser
from mobigrasp.protocol.reliable import RetransmitQueue, SequenceCounter

STEP_US = 1_000
WATCHDOG_US = 250_000  # firmware default watchdog_ms


class StandinHost:
    """A minimal host: HELLO, one reliable command outstanding, SetWheels and heartbeats."""

    def __init__(self, mcu: Mcu, faults: RunFaults) -> None:
        self.mcu, self.faults = mcu, faults
        self.parser = FrameParser()
        self.seq = SequenceCounter()
        self.rq = RetransmitQueue(timeout_us=40_000, max_retries=10)
        self.line_free_us = 0
        self.handshake = False
        self.hello_seq = None
        self.answers: dict[int, int] = {}  # seq -> 0 ACK or NACK reason (latest)
        self.telemetry: list[m.Telemetry] = []
        self.failed: list[int] = []

    def send(self, msg, now_us: int) -> int:
        seq = self.seq.next()
        while msg.RELIABLE and seq in self.rq.in_flight():
            seq = self.seq.next()
        wire = m.encode_message(msg, seq)
        if msg.RELIABLE:
            self.rq.track(seq, wire, now_us)
        self._put(wire, now_us)
        return seq

    def _put(self, wire: bytes, now_us: int) -> None:
        start = max(now_us, self.line_free_us)
        self.line_free_us = start + -(-len(wire) * 10_000_000 // 115_200)
        data, _, _ = self.faults.to_mcu.apply(wire, start)
        if data:
            self.mcu.uart_rx(data, self.faults.to_mcu.deliver_us(start))

    def hello(self, now_us: int) -> None:
        self.handshake = False
        self.rq.clear()
        self.hello_seq = self.send(m.Hello(PROTOCOL_VERSION, "standin", 0), now_us)

    def poll(self, now_us: int) -> None:
        for t_us, data in self.mcu.uart_tx_take():
            data, _, _ = self.faults.to_host.apply(data, t_us)
            for frame in self.parser.feed(data):
                try:
                    msg = m.decode_frame(frame)
                except m.MessageError:
                    continue
                if isinstance(msg, m.Ack | m.Nack):
                    self.rq.ack(msg.acked_seq)
                    self.answers[msg.acked_seq] = getattr(msg, "reason", 0)
                elif isinstance(msg, m.HelloAck):
                    self.rq.ack(self.hello_seq)
                    self.handshake = True
                elif isinstance(msg, m.Telemetry):
                    self.telemetry.append(msg)
        for wire in self.rq.due(now_us):
            self._put(wire, now_us)
        self.failed += self.rq.failed()


@pytest.fixture
def executed(monkeypatch):
    """Every command the firmware carries out: ('servos', targets) / ('wheels', l, r) / ..."""
    log = []
    real_execute = dispatch.execute

    def spy(fw, msg):
        if isinstance(msg, m.SetServos):
            log.append(("servos", msg.targets))
        else:
            log.append((type(msg).__name__,))
        return real_execute(fw, msg)

    monkeypatch.setattr(dispatch, "execute", spy)
    return log


def _spy_wheels(mcu: Mcu, log: list) -> None:
    fw = mcu.firmware
    real = fw.set_wheels

    def spy(left, right):
        log.append(("wheels", left, right))
        real(left, right)

    fw.set_wheels = spy


def _servo_targets(k: int) -> tuple[int, ...]:
    # unique per k and inside the joint table, so each executed command names its origin
    return (0, 0, -1500, -1400, 1500, -1400 + k)


@pytest.mark.parametrize("ber, seed", [
    (1e-4, 1), (1e-3, 2),
    pytest.param(1e-3, 3, marks=pytest.mark.slow), pytest.param(3e-3, 4, marks=pytest.mark.slow),
])
def test_bit_errors_never_execute_corrupt_or_twice_and_reliable_commands_arrive(
        executed, ber, seed):
    faults = RunFaults(FaultPlan(uart_bit_error_rate=ber), seed)
    mcu = Mcu()
    _spy_wheels(mcu, executed)
    host = StandinHost(mcu, faults)
    sent_servos, sent_wheels = [], set()
    end_us = 5_000_000
    for t in range(STEP_US, end_us + 1, STEP_US):
        mcu.advance_to(t)
        host.poll(t)
        if not host.handshake:
            if not host.rq.in_flight() and t % 100_000 == 0:
                host.hello(t)
            continue
        if t % 20_000 == 0:
            w = ((t // 20_000) % 1500 - 700, 50)
            sent_wheels.add(w)
            host.send(m.SetWheels(*w), t)
        if t % 100_000 == 0:
            host.send(m.Heartbeat(t), t)
        if not host.rq.in_flight() and t % 10_000 == 0 and t < end_us - 1_000_000:
            sent_servos.append(_servo_targets(len(sent_servos)))
            host.send(m.SetServos(mode=m.SERVO_MODE_MRAD, targets=sent_servos[-1]), t)
    servos = [e[1] for e in executed if e[0] == "servos"]
    wheels = [e[1:] for e in executed if e[0] == "wheels"]
    assert servos == sent_servos  # each exactly once, in order, none corrupted, none lost
    # liveness: stop-and-wait servo commands keep flowing (a frame of ~20 bytes and its ACK
    # both get through with probability ~0.4 at 3e-3, ~0.85 at 1e-3)
    assert not host.failed and len(sent_servos) > (120 if ber <= 1e-3 else 50)
    assert set(wheels) <= sent_wheels and len(wheels) == len(set(wheels))
    assert {e[0] for e in executed} <= {"servos", "wheels"}
    st_ = mcu.stats()
    assert st_["corrupt_frames"] > 0  # the faults really hit the MCU's parser
    if ber >= 1e-3:
        assert host.rq.retransmits > 0 and st_["duplicates"] > 0  # lost ACKs -> copies
        assert len(wheels) < len(sent_wheels)  # unreliable frames are simply lost


def _run_until_crash(crash_us: int, end_us: int):
    faults = RunFaults(FaultPlan(host_crash_at_s=crash_us / 1e6), 0)
    mcu = Mcu()
    plant = WheelsInTheAir()
    host = StandinHost(mcu, faults)
    duties, pulses = [], []
    host.hello(0)
    for t in range(STEP_US, end_us + 1, STEP_US):
        mcu.advance_to(t)
        mcu.set_encoder_ticks(*plant.step(mcu.wheel_duty(), STEP_US), t)
        duties.append((t, mcu.wheel_duty()))
        pulses.append(tuple(mcu.servo_pulse_ns(ch) for ch in range(6)))
        if faults.host_crashed(t):
            continue  # a dead host: nothing read, nothing written
        host.poll(t)
        if host.handshake and t % 20_000 == 0:
            host.send(m.SetWheels(300, -200), t)
        if host.handshake and t == 200_000:
            host.send(m.SetServos(mode=m.SERVO_MODE_MRAD, targets=_servo_targets(5)), t)
    return mcu, host, duties, pulses


@examples(8)
@given(crash_us=st.integers(400_000, 1_500_000))
def test_host_crash_stops_the_wheels_within_watchdog_plus_50ms(crash_us):
    end_us = crash_us + 1_000_000
    mcu, host, duties, pulses = _run_until_crash(crash_us, end_us)
    running = [d for t, d in duties if t <= crash_us]
    assert running[-1] != (0, 0)  # the wheels were driven when the host died
    after = [(t, d) for t, d in duties if t > crash_us]
    stopped_at = next(t for t, d in after if d == (0, 0))
    assert stopped_at <= crash_us + WATCHDOG_US + 50_000
    assert all(d == (0, 0) for t, d in after if t >= stopped_at)  # and they stay stopped
    k = stopped_at // STEP_US
    assert len(set(pulses[k + 40:])) == 1  # arm held (after the period in flight)
    assert mcu.firmware.watchdog_trips == 1 and mcu.firmware.watchdog_tripped


def test_watchdog_period_comes_from_the_parameter():
    assert mcu_param_default("watchdog_ms") * 1000 == WATCHDOG_US


def mcu_param_default(name: str) -> int:
    return Mcu().firmware.params.get(param_id(name))


def test_mcu_reset_needs_a_new_handshake_then_works_again(executed):
    reset_us = 1_000_000
    faults = RunFaults(FaultPlan(mcu_reset_at_s=reset_us / 1e6), 0)
    mcu = Mcu()
    _spy_wheels(mcu, executed)
    host = StandinHost(mcu, faults)
    host.hello(0)
    noticed_us = rehello_us = None
    last_time = -1
    probe_seq = None
    for t in range(STEP_US, 2_500_001, STEP_US):
        if faults.mcu_reset_due(t - STEP_US, t):
            mcu.reset()
        mcu.advance_to(t)
        n_tel = len(host.telemetry)
        host.poll(t)
        for tel in host.telemetry[n_tel:]:
            went_back = tel.time_us < last_time
            last_time = tel.time_us
            if t > 50_000 and (tel.flags & m.FLAG_RESET or went_back) and noticed_us is None:
                noticed_us = t
                host.hello(t)  # resynchronise
                rehello_us = t
        if t % 20_000 == 0:
            host.send(m.SetWheels(100, 100), t)
        if t == reset_us + STEP_US:  # a command the reset MCU gets before any new HELLO
            probe_seq = host.send(m.SetServos(mode=m.SERVO_MODE_MRAD,
                                              targets=_servo_targets(999)), t)
        elif t % 50_000 == 0 and not host.rq.in_flight():
            host.send(m.SetServos(mode=m.SERVO_MODE_MRAD, targets=_servo_targets(t // 50_000)),
                      t)
    assert noticed_us is not None and reset_us < noticed_us <= reset_us + 60_000
    assert host.handshake and rehello_us == noticed_us
    servo_times = [e for e in executed if e[0] == "servos"]
    assert servo_times and mcu.firmware.handshake
    # between the reset and the new HELLO nothing was executed: the probe was refused
    assert host.answers.get(probe_seq) == m.NACK_NOT_READY
    assert ("servos", _servo_targets(999)) not in executed
    assert mcu.firmware.not_ready >= 1
    # commands sent after the new handshake are executed again
    last_targets = servo_times[-1][1]
    assert last_targets[5] > -1400 + reset_us // 50_000
    assert mcu.wheel_duty() != (0, 0)
