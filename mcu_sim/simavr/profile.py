"""The AVR's timing as simavr measured it, each figure beside the firmware's budget.

``profile_stats(raw)`` turns SimavrMcu.profile() into flat integer counters (they go into the
run's ``summary.json`` under ``mcu`` with the other MCU counters, prefixed ``avr_``);
``profile_rows(stats)`` gives the table of ``mobigrasp profile --mcu simavr``: figure, worst
case, budget, and whether the budget was exceeded (with ``--mcu python``, the load row alone:
the model's charged cycles, mcu_sim/firmware/cycles.py). The budgets follow from the line rate
(docs/firmware.md, "simavr"):

- one byte time at 117 647 baud 8N1 is 1360 cycles (85 µs); the part buffers two received bytes,
  so any interrupt handler, and any stretch with interrupts off, must end within half a byte
  time (680 cycles) for a byte that arrives behind it to reach the ring in time;
- a received byte must be in the RX ring within 86.8 µs (1389 cycles, the byte time at the
  nominal 115 200 baud) of its stop bit;
- one main-loop pass must end before the RX ring (127 bytes) fills at the full line rate;
- the deepest stack must stay within the static worst case of mcu_sim/firmware/sram.py (main's
  deepest chain plus the deepest handler), which is what the SRAM budget reserves;
- the AVR is busy (not asleep) at most half the time.
"""

from __future__ import annotations

from mobigrasp.mcu_sim.firmware.sram import RX_RING_BYTES, stack_bytes

BYTE_CYCLES = 1360
ISR_BUDGET_CYCLES = BYTE_CYCLES // 2
IRQ_OFF_BUDGET_CYCLES = BYTE_CYCLES // 2
RX_LATENCY_BUDGET_CYCLES = 1389  # 86.8 µs x 16
LOOP_BUDGET_CYCLES = (RX_RING_BYTES - 1) * BYTE_CYCLES
LOAD_BUDGET_PERMILLE = 500

# ATmega128 interrupt vectors the firmware uses (datasheet, "Reset and Interrupt Vectors")
VECTOR_NAMES = {1: "INT0", 2: "INT1", 3: "INT2", 4: "INT3", 5: "INT4", 6: "INT5", 7: "INT6",
                8: "INT7", 9: "TIMER2_COMP", 10: "TIMER2_OVF", 14: "TIMER1_OVF",
                16: "TIMER0_OVF", 18: "USART0_RX", 19: "USART0_UDRE", 20: "USART0_TX"}


def vector_name(v: int) -> str:
    """Datasheet name of interrupt vector ``v``."""
    return VECTOR_NAMES.get(v, f"VECTOR{v}")


def profile_stats(raw: dict) -> dict[str, int]:
    """SimavrMcu.profile() as flat ``avr_*`` integer counters."""
    out = {f"avr_isr_max_cycles_{vector_name(v)}": int(c)
           for v, c in sorted(raw["isr_max_cycles"].items())}
    total = int(raw["total_cycles"]) or 1
    out.update({
        "avr_irq_off_max_cycles": int(raw["irq_off_max_cycles"]),
        "avr_irq_off_max_from_pc": int(raw["irq_off_max_from_pc"]),
        "avr_irq_off_max_to_pc": int(raw["irq_off_max_to_pc"]),
        "avr_rx_latency_max_cycles": int(raw["rx_latency_max_cycles"]),
        "avr_loop_max_cycles": int(raw["loop_max_cycles"]),
        "avr_loop_passes": int(raw["loop_passes"]),
        "avr_load_permille": 1000 - int(raw["sleep_cycles"]) * 1000 // total,
        "avr_stack_max_bytes": int(raw["stack_depth_bytes"]),
        "avr_rx_line_lost": int(raw["rx_line_lost"]),
    })
    return out


def profile_rows(stats: dict) -> list[dict]:
    """Rows (figure, worst, budget, unit, exceeded) from the ``avr_*`` counters of ``stats``."""
    rows = []

    def row(name: str, worst: int, budget: int, unit: str, where: str = "") -> None:
        rows.append({"figure": name, "worst": worst, "budget": budget, "unit": unit,
                     "exceeded": worst > budget, "where": where})

    for key in sorted(k for k in stats if k.startswith("avr_isr_max_cycles_")):
        row(f"ISR {key.removeprefix('avr_isr_max_cycles_')}", stats[key], ISR_BUDGET_CYCLES,
            "cycles")
    if "avr_loop_max_cycles" in stats:
        row("main-loop pass", stats["avr_loop_max_cycles"], LOOP_BUDGET_CYCLES, "cycles")
        # where the longest stretch began and ended (flash byte addresses: avr-addr2line or
        # avr-objdump -d of the ELF name the code; a vector's address when a handler began it)
        span = ""
        if "avr_irq_off_max_from_pc" in stats:
            span = (f"pc 0x{stats['avr_irq_off_max_from_pc']:04x}"
                    f"..0x{stats['avr_irq_off_max_to_pc']:04x}")
        row("interrupts off", stats["avr_irq_off_max_cycles"], IRQ_OFF_BUDGET_CYCLES, "cycles",
            span)
        row("UART RX latency", stats["avr_rx_latency_max_cycles"], RX_LATENCY_BUDGET_CYCLES,
            "cycles")
        row("AVR load", stats["avr_load_permille"], LOAD_BUDGET_PERMILLE, "permille")
        row("deepest stack", stats["avr_stack_max_bytes"], stack_bytes(), "bytes")
        row("RX bytes lost on the line", stats["avr_rx_line_lost"], 0, "bytes")
    elif "avr_load_permille" in stats:  # the Python model's charged cycles (firmware/cycles.py)
        row("AVR load (model)", stats["avr_load_permille"], LOAD_BUDGET_PERMILLE, "permille")
    return rows


def format_rows(rows: list[dict]) -> str:
    """The table as text; a row over its budget is marked ``EXCEEDED``."""
    model = [r["figure"] for r in rows] == ["AVR load (model)"]
    title = "AVR (Python model)" if model else "AVR (simavr)"
    lines = [f"{title:<28}{'worst':>10}{'budget':>10}  unit"]
    for r in rows:
        mark = "  EXCEEDED" if r["exceeded"] else ""
        where = f"  ({r['where']})" if r.get("where") else ""
        lines.append(f"{r['figure']:<28}{r['worst']:>10}{r['budget']:>10}  {r['unit']}{mark}"
                     f"{where}")
    broken = [r["figure"] for r in rows if r["exceeded"]]
    lines.append("budgets exceeded: " + (", ".join(broken) if broken else "none"))
    return "\n".join(lines)
