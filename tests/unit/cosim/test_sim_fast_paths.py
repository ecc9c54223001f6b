"""The SIM side's fast paths give exactly what the general paths give (perf round 3).

- FaultedMcu with a plan that leaves the coupling step alone binds the MCU's own calls and
  hands TX chunks on as they are: a closed-loop run with those shortcuts removed (the general
  wrapper methods) gives the same trace, safety and fault blocks and MCU counters.
- SafetyMonitor judges the servo pulses only when they change: an out-of-limit pulse held for
  n steps still counts n times.
- A QuadratureEncoder told the count it already stands at keeps its old segment: the counts the
  firmware sees are those of the encoder without that shortcut.
- WorldPlant casts only the sonar the MCU fired: the same ranges as the whole ring's cast.
"""

from __future__ import annotations

from faulted_loop import faulted_loop
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.mcu_sim.avr.encoder import QuadratureEncoder
from mobigrasp.mcu_sim.faults import FaultPlan
from mobigrasp.mcu_sim.faults.safety import SafetyMonitor
from mobigrasp.services.run_job import resolve_scenario

_SHORTCUTS = ("advance_to", "advance_outputs", "wheel_duty", "set_encoder_ticks",
              "uart_tx_take", "servo_pulses_us")


def _run(tmp_path, plan: FaultPlan, general: bool, seconds: float = 1.5):
    bound: list[str] = []

    def strip(mcu) -> None:
        bound.extend(name for name in _SHORTCUTS if name in vars(mcu))
        if general:
            for name in bound:
                del mcu.__dict__[name]  # back to the class's general methods

    run = faulted_loop(tmp_path, plan, seconds, name=f"trace-{general}.jsonl", before=strip,
                       session=lambda mcu, plant: {"truth": plant.truth})
    return (run.trace.sha256(), run.faults, run.safety, run.mcu.inner.stats(), run.rig.stats,
            run.res.end_us), bound


def test_quiet_wrapper_shortcuts_change_nothing(tmp_path):
    fast, bound = _run(tmp_path, FaultPlan(), general=False)
    assert set(bound) == set(_SHORTCUTS)  # an empty plan takes every shortcut
    slow, _ = _run(tmp_path, FaultPlan(), general=True)
    assert fast == slow
    assert fast[1]["uart_to_host"]["bytes_in"] > 0  # TX bytes counted on the shortcut too


def test_byte_faults_keep_the_general_tx_path(tmp_path):
    plan = FaultPlan(uart_bit_error_rate=1e-3)
    fast, bound = _run(tmp_path, plan, general=False, seconds=1.0)
    assert "uart_tx_take" not in bound and "advance_outputs" in bound
    slow, _ = _run(tmp_path, plan, general=True, seconds=1.0)
    assert fast == slow


def test_held_out_of_limit_pulse_counts_every_step():
    mon = SafetyMonitor()
    bad = (1500.0, 1500.0, 1500.0, 1500.0, 1500.0, 3000.0)  # waist far past its limit
    good = (1500.0,) * 6
    for k in range(5):
        mon.observe(k * 1000, (0, 0), bad, False, True)
    for k in range(5, 8):
        mon.observe(k * 1000, (0, 0), good, False, True)
    mon.observe(9000, (0, 0), list(bad), False, True)  # a list of the same values: judged too
    assert mon.servo_out_of_limits == 6


class _PlainEncoder(QuadratureEncoder):
    """The encoder without the standing-shaft shortcut (reference)."""

    def set_ticks(self, count: int, t_cycle: int, now_cycle: int) -> None:
        self._new_segment(count, t_cycle, now_cycle)  # always a new segment


@examples(150)
@given(st.lists(st.tuples(st.integers(-3, 3), st.integers(0, 5), st.integers(1, 5)),
                min_size=1, max_size=40))
def test_encoder_shortcut_sees_the_same_edges(steps):
    fast, ref = QuadratureEncoder("f"), _PlainEncoder("r")
    count, now = 0, 0
    for delta, ahead, looks in steps:
        count += delta if delta % 2 else 0  # often the same count again
        for enc in (fast, ref):
            enc.set_ticks(count, now + ahead * 40_000, now)
        for k in range(looks):  # the MCU's events until the next coupling step
            cycle = now + (k + 1) * 40_000 * 3 // looks
            assert fast.take_edges(cycle) == ref.take_edges(cycle)
        now += 40_000 * 3


def test_sonar_one_by_one_equals_the_ring():
    _, sc = resolve_scenario("paper001-sim1")
    plant = WorldPlant(sc, 3)
    assert plant._sonar_one_by_one
    plant.world.set_wheel_duty(120, 90)
    for t_us in (50_000, 400_000, 900_000):
        plant.step_to(t_us)
        ring = plant.world.sonar_ranges_m()
        got = [plant.sonar_range_m(i) for i in (3, 0, 4, 1, 2, 3)]
        assert got == [ring[i] for i in (3, 0, 4, 1, 2, 3)]
        assert any(r is not None for r in ring)
    assert plant.sonar_range_m(7) is None and plant.sonar_range_m(-1) is None
