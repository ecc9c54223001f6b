"""Sequential polling of up to five sonars (paper 001): one sonar per time slot.

At the start of a slot (``sonar_slot_ms``, default 30 ms, long enough for a 2.5 m echo of 14.6 ms
and for its reverberation to die) the firmware triggers the next fitted sonar; the echo interrupt
stamps the rising and falling edges in µs. At the end of the slot the width gives the range
``d_mm = width_us x 343 / 2000`` (speed of sound 343 m/s, there and back); no falling edge, or a
width beyond 2.5 m, gives SONAR_NO_ECHO. Sonars beyond ``sonar_count`` report SONAR_NO_ECHO.
"""

from __future__ import annotations

SONARS_MAX = 5
NO_ECHO = 0xFFFF
MAX_RANGE_MM = 2500


def width_to_mm(width_us: int) -> int:
    """Range in mm from the echo width in µs (343 m/s, round trip)."""
    return width_us * 343 // 2000


class SonarTask:
    """Slot state and the latest range of every sonar (uint16 in C)."""

    def __init__(self) -> None:
        self.range_mm = [NO_ECHO] * SONARS_MAX
        self.index = 0
        self.rise_us = 0
        self.fall_us = 0
        self.have_rise = False
        self.have_fall = False
        self.next_slot_us = 0
        self.active = False

    def reset(self, now_us: int) -> None:
        """Power-on: nothing measured, first slot now."""
        for i in range(SONARS_MAX):
            self.range_mm[i] = NO_ECHO
        self.index = SONARS_MAX - 1  # so the first slot polls sonar 0
        self.have_rise = self.have_fall = False
        self.active = False
        self.next_slot_us = now_us

    def on_echo(self, index: int, level: int, t_us: int) -> None:
        """Echo pin interrupt: stamp the edges of the sonar in its slot; others are ignored."""
        if not self.active or index != self.index:
            return
        if level:
            self.rise_us = t_us
            self.have_rise = True
        elif self.have_rise:
            self.fall_us = t_us
            self.have_fall = True

    def end_slot(self) -> None:
        """Close the current slot: turn its edges into a range (or NO_ECHO)."""
        if not self.active:
            return
        mm = NO_ECHO
        if self.have_rise and self.have_fall:
            mm = width_to_mm(self.fall_us - self.rise_us)
            if mm > MAX_RANGE_MM:
                mm = NO_ECHO
        self.range_mm[self.index] = mm
        self.active = False

    def start_slot(self, count: int, now_us: int, slot_us: int) -> int | None:
        """Pick the next sonar to trigger (None when none are fitted); schedule the slot's end."""
        self.next_slot_us = now_us + slot_us
        for i in range(count, SONARS_MAX):
            self.range_mm[i] = NO_ECHO
        if count <= 0:
            return None
        self.index = (self.index + 1) % count if self.index < count else 0
        self.have_rise = self.have_fall = False
        self.active = True
        return self.index
