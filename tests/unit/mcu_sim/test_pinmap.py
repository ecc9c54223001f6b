"""The pin map can be wired on an ATmega128, and board.h / docs/firmware.md are its copies."""

from pathlib import Path

from mobigrasp.mcu_sim.avr import pinmap

ROOT = Path(__file__).resolve().parents[3]


def test_no_pin_has_two_signals_and_every_function_is_on_a_capable_pin():
    assert pinmap.check() == []
    pins = [pin for _, pin, _, _ in pinmap.BOARD]
    assert len(pins) == len(set(pins))
    for sig, pin, fn, _ in pinmap.BOARD:
        assert fn == pinmap.GPIO or fn in pinmap.PART_PINS[pin], (sig, pin, fn)


def test_outputs_and_interrupt_inputs_use_their_hardware():
    pins = pinmap.by_signal()
    servo_fns = [pins[f"SERVO{ch}"][1] for ch in range(6)]
    assert servo_fns == ["OC1A", "OC1B", "OC1C", "OC3A", "OC3B", "OC3C"]
    for sig in ("ENC_L_A", "ENC_L_B", "ENC_R_A", "ENC_R_B", "SONAR_ECHO"):
        assert pins[sig][1].startswith("INT"), sig
    assert pins["HOST_RXD"][1] == "RXD0" and pins["HOST_TXD"][1] == "TXD0"


def test_check_finds_the_documented_conflicts():
    # the wiring the docs had before: PWM and direction on PB4, OC2 and OC1C both on PB7,
    # OC3B as well as INT4 on PE4
    bad = (("A", "PB4", "OC0", ""), ("B", "PB4", "GPIO", ""), ("C", "PB7", "OC2", ""),
           ("D", "PB7", "OC1C", ""), ("E", "PE4", "OC3B", ""), ("F", "PE4", "INT4", ""),
           ("G", "PC0", "INT0", ""))
    saved = pinmap.BOARD
    try:
        pinmap.BOARD = bad
        problems = pinmap.check()
    finally:
        pinmap.BOARD = saved
    assert any("PB4" in p and "A" in p and "B" in p for p in problems)
    assert any("PB7" in p for p in problems)
    assert any("PE4" in p for p in problems)
    assert any(p.startswith("G:") and "cannot be INT0" in p for p in problems)


def test_board_h_is_generated_from_the_table():
    assert (ROOT / "firmware" / "board.h").read_text() == pinmap.header()


def test_docs_pin_table_is_generated_from_the_table():
    text = (ROOT / "docs" / "firmware.md").read_text()
    begin = text.index("<!-- pinmap:begin -->\n") + len("<!-- pinmap:begin -->\n")
    end = text.index("<!-- pinmap:end -->")
    assert text[begin:end] == pinmap.markdown()
