"""host/mcu_watch: the host notices an MCU reset from the telemetry."""

from mobigrasp.host.mcu_watch import McuWatch
from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.protocol import messages as m
from mobigrasp.protocol.frame import PROTOCOL_VERSION, FrameParser

UP = m.FLAG_HANDSHAKE


def test_reasons():
    w = McuWatch()
    assert w.feed(1000, m.FLAG_RESET) is None  # boot telemetry before any session: normal
    w.handshake_done()
    assert w.feed(21_000, UP) is None and w.feed(41_000, UP | m.FLAG_WATCHDOG) is None
    assert w.feed(500, m.FLAG_RESET) == "flag_reset" and w.resets == 1
    assert w.feed(20_500, 0) is None  # waiting for the new HELLO_ACK: nothing new
    w.handshake_done()
    assert w.feed(40_500, 0) == "handshake_lost"
    w.handshake_done()
    assert w.feed(10_000, UP) == "time_went_back" and w.resets == 3


def test_u32_wrap_is_not_a_reset():
    w = McuWatch()
    w.handshake_done()
    assert w.feed(2**32 - 5_000, UP) is None
    assert w.feed(15_000, UP) is None and w.resets == 0


def test_with_the_real_firmware():
    mcu, parser, w = Mcu(), FrameParser(), McuWatch()
    mcu.uart_rx(m.encode_message(m.Hello(PROTOCOL_VERSION, "t", 0), 0), 0)
    reasons = []
    for t in range(1000, 1_000_001, 1000):
        if t == 600_000:
            mcu.reset()
        mcu.advance_to(t)
        if t % 50_000 == 0 and w.session_up:
            mcu.uart_rx(m.encode_message(m.Heartbeat(t), (t // 50_000) & 0xFF), t)
        for _, data in mcu.uart_tx_take():
            for frame in parser.feed(data):
                msg = m.decode_frame(frame)
                if isinstance(msg, m.HelloAck):
                    w.handshake_done()
                elif isinstance(msg, m.Telemetry):
                    r = w.feed(msg.time_us, msg.flags)
                    if r:
                        reasons.append((t, r))
    assert len(reasons) == 1 and 600_000 <= reasons[0][0] <= 620_000
    assert reasons[0][1] in ("flag_reset", "time_went_back")
