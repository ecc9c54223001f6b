"""Two-channel quadrature wheel encoders read through pin-change / external interrupts.

The world owns the physical shaft: it tells the model the cumulative quadrature count at a time
(``set_ticks``). Between the previous known point and that time the edges are spread linearly, as
a shaft turning at constant speed would produce them, so the count the firmware has seen at any
instant is ``floor`` of the interpolated position. On the part every A/B edge fires INT4..INT7 and
the ISR adds +1 or -1 from the pin-state table; the model hands the firmware the number of edges
since its last look (``take_edges``), which equals that many ISR calls of one sign because the
segment between two known points has a single direction. An MCU reset clears the firmware's count,
not the shaft, so ``take_edges`` keeps working across resets.
"""

from __future__ import annotations


class QuadratureEncoder:
    """One wheel's encoder: physical position in quadrature counts, timed in CPU cycles."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._t0 = 0
        self._c0 = 0
        self._t1 = 0
        self._c1 = 0
        self._taken = 0
        self.bad_inputs = 0

    def position_at(self, cycle: int) -> int:
        """Quadrature count of the shaft at ``cycle`` (edges strictly by then)."""
        if cycle >= self._t1:
            return self._c1
        if cycle <= self._t0:
            return self._c0
        span = self._t1 - self._t0
        dc = self._c1 - self._c0
        moved = (abs(dc) * (cycle - self._t0)) // span  # whole edges that have occurred
        return self._c0 + moved if dc >= 0 else self._c0 - moved

    def set_ticks(self, count: int, t_cycle: int, now_cycle: int) -> None:
        """The shaft is at ``count`` at ``t_cycle``: in the future, edges spread from now until
        then; at or before now, the count applies at once. Non-integers are counted and ignored."""
        if isinstance(count, bool) or not isinstance(count, int):
            self.bad_inputs += 1
            return
        if count == self._c1 and now_cycle >= self._t1:
            # the shaft stands at the count it reached (a standing wheel): the segment
            # [now, t_cycle] would be flat at that count, which position_at returns already
            return
        self._new_segment(count, t_cycle, now_cycle)

    def _new_segment(self, count: int, t_cycle: int, now_cycle: int) -> None:
        """Edges from the position now to ``count`` at ``t_cycle`` (at once if not later)."""
        here = self.position_at(now_cycle)
        if t_cycle <= now_cycle:
            self._t0 = self._t1 = now_cycle
            self._c0 = self._c1 = count
        else:
            self._t0, self._c0 = now_cycle, here
            self._t1, self._c1 = t_cycle, count

    def edges_pending(self, cycle: int) -> bool:
        """Whether :meth:`take_edges` at ``cycle`` could return edges: the shaft is still
        moving, or stands where the last call did not see it (False: it would return 0)."""
        return cycle < self._t1 or self._c1 != self._taken

    def take_edges(self, cycle: int) -> int:
        """Signed number of edges between the previous call and ``cycle`` (what the ISR counted)."""
        pos = self.position_at(cycle)
        delta = pos - self._taken
        self._taken = pos
        return delta
