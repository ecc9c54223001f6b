"""The board's pin map, written once: what each ATmega128 pin can do and what the board uses.

``PART_PINS`` is the datasheet (ATmega128, "Pin Configurations" and the "Alternate Functions of
Port A..G" tables): every I/O pin with the alternate functions the part offers on it. ``BOARD`` is
the wiring: one row per signal, the pin and the function it uses there. ``SENSORS`` declares
each sensor once: its signals (rows of ``BOARD``), the world's model of it, the plant reading and
the MCU input the rig wires together (cosim/rig.py reads this table: a ``COUPLED`` sensor is read
from the plant at every coupling step and given to the MCU, a ``POLLED`` one is asked for by the
MCU when its firmware samples it) and the telemetry fields that carry it to the host.
``firmware/board.h`` and the pin and sensor tables of ``docs/firmware.md`` are generated from
these tables (``python -m mobigrasp.mcu_sim.avr.pinmap header|markdown``) and
``tests/test_pinmap.py`` checks that the committed copies match, that no pin carries two signals,
that every signal sits on a pin that has its function and that every sensor names real signals,
plant and MCU methods and telemetry fields.

Why the wiring is what it is (the part's constraints, datasheet facts):

- the six servo pulses need the six compare outputs of the two 16-bit timers (OC1A/B/C on
  PB5/PB6/PB7, OC3A/B/C on PE3/PE4/PE5); OC1C and OC2 share PB7, so Timer2 cannot drive a pin
  and the right wheel's PWM is made by Timer2's compare and overflow interrupts on a plain port
  pin (same 976.6 Hz fast-PWM timing, OCR2 still double-buffered at BOTTOM);
- PE4/PE5 being OC3B/OC3C, INT4/INT5 are gone: the encoders use INT0..INT3 (PD0..PD3; TWI and
  USART1 are not used) and the sonar echo uses INT6;
- with ICR1/ICR3 as TOP (mode 14) input capture is off, so the echo is timed by an
  any-edge external interrupt plus a clock read; the five echo outputs are OR-ed onto INT6
  (only the sonar triggered in the current slot ever answers);
- PE0/PE1 are RXD0/TXD0 and also the ISP lines PDI/PDO: the host UART is connected through
  series resistors so a programmer can override it (docs/firmware.md, "Flashing").
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

# Datasheet: pin -> alternate functions (GPIO is implied for every pin).
PART_PINS: dict[str, tuple[str, ...]] = {
    "PA0": ("AD0",), "PA1": ("AD1",), "PA2": ("AD2",), "PA3": ("AD3",),
    "PA4": ("AD4",), "PA5": ("AD5",), "PA6": ("AD6",), "PA7": ("AD7",),
    "PB0": ("SS",), "PB1": ("SCK",), "PB2": ("MOSI",), "PB3": ("MISO",),
    "PB4": ("OC0",), "PB5": ("OC1A",), "PB6": ("OC1B",), "PB7": ("OC2", "OC1C"),
    "PC0": ("A8",), "PC1": ("A9",), "PC2": ("A10",), "PC3": ("A11",),
    "PC4": ("A12",), "PC5": ("A13",), "PC6": ("A14",), "PC7": ("A15",),
    "PD0": ("INT0", "SCL"), "PD1": ("INT1", "SDA"), "PD2": ("INT2", "RXD1"),
    "PD3": ("INT3", "TXD1"), "PD4": ("ICP1",), "PD5": ("XCK1",), "PD6": ("T1",),
    "PD7": ("T2",),
    "PE0": ("RXD0", "PDI"), "PE1": ("TXD0", "PDO"), "PE2": ("XCK0", "AIN0"),
    "PE3": ("OC3A", "AIN1"), "PE4": ("OC3B", "INT4"), "PE5": ("OC3C", "INT5"),
    "PE6": ("T3", "INT6"), "PE7": ("ICP3", "INT7"),
    "PF0": ("ADC0",), "PF1": ("ADC1",), "PF2": ("ADC2",), "PF3": ("ADC3",),
    "PF4": ("ADC4", "TCK"), "PF5": ("ADC5", "TMS"), "PF6": ("ADC6", "TDO"),
    "PF7": ("ADC7", "TDI"),
    "PG0": ("WR",), "PG1": ("RD",), "PG2": ("ALE",), "PG3": ("TOSC2",), "PG4": ("TOSC1",),
}
GPIO = "GPIO"

# The wiring: (signal, pin, function used on that pin, what it is for).
BOARD: tuple[tuple[str, str, str, str], ...] = (
    ("SERVO0", "PB5", "OC1A", "servo ch0 gripper, Timer1 mode 14"),
    ("SERVO1", "PB6", "OC1B", "servo ch1 wrist roll"),
    ("SERVO2", "PB7", "OC1C", "servo ch2 wrist pitch"),
    ("SERVO3", "PE3", "OC3A", "servo ch3 elbow, Timer3 mode 14"),
    ("SERVO4", "PE4", "OC3B", "servo ch4 shoulder"),
    ("SERVO5", "PE5", "OC3C", "servo ch5 waist"),
    ("WHEEL_L_PWM", "PB4", "OC0", "left wheel PWM, Timer0 fast PWM clk/64"),
    ("WHEEL_L_DIR", "PA0", GPIO, "left wheel direction (1 = reverse)"),
    ("WHEEL_R_PWM", "PA2", GPIO, "right wheel PWM, Timer2 fast PWM clk/64 by its interrupts"),
    ("WHEEL_R_DIR", "PA1", GPIO, "right wheel direction (1 = reverse)"),
    ("ENC_L_A", "PD0", "INT0", "left encoder channel A, any edge"),
    ("ENC_L_B", "PD1", "INT1", "left encoder channel B, any edge"),
    ("ENC_R_A", "PD2", "INT2", "right encoder channel A, any edge"),
    ("ENC_R_B", "PD3", "INT3", "right encoder channel B, any edge"),
    ("SONAR_TRIG0", "PC0", GPIO, "sonar 0 trigger"),
    ("SONAR_TRIG1", "PC1", GPIO, "sonar 1 trigger"),
    ("SONAR_TRIG2", "PC2", GPIO, "sonar 2 trigger"),
    ("SONAR_TRIG3", "PC3", GPIO, "sonar 3 trigger"),
    ("SONAR_TRIG4", "PC4", GPIO, "sonar 4 trigger"),
    ("SONAR_ECHO", "PE6", "INT6", "echo of sonars 0..4 OR-ed, any edge"),
    ("HOST_RXD", "PE0", "RXD0", "USART0 receive, from the S3C2440's TXD"),
    ("HOST_TXD", "PE1", "TXD0", "USART0 transmit, to the S3C2440's RXD"),
)


# How the rig feeds a sensor's reading from the plant to the MCU.
COUPLED = "coupled"  # read at every coupling step: mcu.<mcu_input>(*plant.<plant_reading>(), t_us)
POLLED = "polled"  # mcu.<mcu_input>(provider); the firmware calls provider(index) when it
# samples, which reads plant.<plant_reading>(index) (once per index and coupling step)
FEEDS = (COUPLED, POLLED)


@dataclass(frozen=True)
class Sensor:
    """A sensor of the board, declared once (the module docstring)."""

    name: str
    signals: tuple[str, ...]  # its rows of BOARD
    world_model: str  # what models it in the world (mcu_sim/world/)
    plant_reading: str  # the Plant method giving its reading (cosim/plant.py)
    mcu_input: str  # the McuBackend method the reading goes to (mcu_sim/backend.py)
    feed: str  # COUPLED or POLLED
    telemetry: tuple[str, ...]  # fields of TELEMETRY (protocol/messages.py) carrying it


SENSORS: tuple[Sensor, ...] = (
    Sensor("wheel_encoders", ("ENC_L_A", "ENC_L_B", "ENC_R_A", "ENC_R_B"),
           "mcu_sim/world/base.py: the wheels' rotation in quadrature counts",
           "encoder_ticks", "set_encoder_ticks", COUPLED, ("enc_left", "enc_right")),
    Sensor("sonar", ("SONAR_TRIG0", "SONAR_TRIG1", "SONAR_TRIG2", "SONAR_TRIG3", "SONAR_TRIG4",
                     "SONAR_ECHO"),
           "mcu_sim/world/sonar.py: the ring's ranges, cone and noise (001 §IV)",
           "sonar_range_m", "set_sonar_provider", POLLED, ("sonar_mm",)),
)


def by_signal() -> dict[str, tuple[str, str]]:
    """signal -> (pin, function)."""
    return {sig: (pin, fn) for sig, pin, fn, _ in BOARD}


def check() -> list[str]:
    """Every way the wiring breaks the part (empty when it can be built)."""
    problems: list[str] = []
    users: dict[str, str] = {}
    signals: set[str] = set()
    for sig, pin, fn, _ in BOARD:
        if sig in signals:
            problems.append(f"{sig}: listed twice")
        signals.add(sig)
        if pin not in PART_PINS:
            problems.append(f"{sig}: {pin} is not an ATmega128 I/O pin")
            continue
        if pin in users:
            problems.append(f"{pin}: both {users[pin]} and {sig}")
        users[pin] = sig
        if fn != GPIO and fn not in PART_PINS[pin]:
            problems.append(f"{sig}: {pin} cannot be {fn} (it offers {PART_PINS[pin]})")
    owner: dict[str, str] = {}  # signal -> the sensor it belongs to
    names: set[str] = set()
    for sensor in SENSORS:
        if sensor.name in names:
            problems.append(f"sensor {sensor.name}: listed twice")
        names.add(sensor.name)
        if sensor.feed not in FEEDS:
            problems.append(f"sensor {sensor.name}: feed {sensor.feed!r} is not one of {FEEDS}")
        for sig in sensor.signals:
            if sig not in signals:
                problems.append(f"sensor {sensor.name}: {sig} is not a signal of BOARD")
            elif sig in owner:
                problems.append(f"sensor {sensor.name}: {sig} is also {owner[sig]}'s")
            owner[sig] = sensor.name
    return problems


def header() -> str:
    """Text of firmware/board.h."""
    lines = [
        "/* board.h: the pin map, generated by `python -m mobigrasp.mcu_sim.avr.pinmap header`",
        " * from mcu_sim/avr/pinmap.py (do not edit; tests/test_pinmap.py checks it). */",
        "#ifndef MOBIGRASP_BOARD_H",
        "#define MOBIGRASP_BOARD_H",
        "",
    ]
    for sig, pin, fn, what in BOARD:
        port, bit = pin[1], int(pin[2])
        lines.append(f"/* {sig}: {pin} as {fn}, {what} */")
        lines.append(f"#define {sig}_PORT PORT{port}")
        lines.append(f"#define {sig}_DDR DDR{port}")
        lines.append(f"#define {sig}_PIN PIN{port}")
        lines.append(f"#define {sig}_BIT {bit}")
    lines += ["", "/* Sensors: their signals and the telemetry fields that carry them */"]
    for sensor in SENSORS:
        lines.append(f"/* {sensor.name}: {' '.join(sensor.signals)} -> "
                     f"{', '.join(sensor.telemetry) or 'no telemetry field'} */")
    lines += ["", "#endif", ""]
    return "\n".join(lines)


def markdown() -> str:
    """The pin and sensor tables of docs/firmware.md."""
    rows = ["| signal | pin | function | use |", "|---|---|---|---|"]
    rows += [f"| `{sig}` | {pin} | {fn} | {what} |" for sig, pin, fn, what in BOARD]
    rows += ["", "| sensor | signals | world model | rig: plant -> MCU | telemetry |",
             "|---|---|---|---|---|"]
    rows += [f"| `{s.name}` | {', '.join(f'`{sig}`' for sig in s.signals)} | {s.world_model} | "
             f"`{s.plant_reading}` -> `{s.mcu_input}` ({s.feed}) | "
             f"{', '.join(f'`{f}`' for f in s.telemetry)} |" for s in SENSORS]
    return "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``header`` or ``markdown``: print the generated text."""
    args = sys.argv[1:] if argv is None else argv
    if args not in (["header"], ["markdown"]):
        print("usage: python -m mobigrasp.mcu_sim.avr.pinmap header|markdown", file=sys.stderr)
        return 2
    sys.stdout.write(header() if args[0] == "header" else markdown())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
