"""Running statistics of one host stage's modelled time, in memory that does not grow with the run.

A stage (control step, protocol, a detector) is charged tens of thousands of times in a
simulated hour; keeping every duration grew the host by megabytes per hour. Calls, total and
maximum are exact running figures; the 95th percentile (nearest rank, as ``stage_summary``)
comes from a histogram whose buckets are exact below 2048 µs and keep the 11 leading bits above
(the reported value is at most 0.1 % low), so the histogram has at most 1024 buckets per power
of two of µs, however long the run. The means are integer ratios to the millionth
(:func:`micro_ratio`), so the C host prints the same decimal text.
"""

from __future__ import annotations

EXACT_BELOW_US = 2048
_MANTISSA_BITS = EXACT_BELOW_US.bit_length() - 1  # 11: 2048 is the first value rounded


def bucket_of(us: int) -> int:
    """The histogram bucket of ``us``: itself below 2048, else ``us`` with its 11 leading bits."""
    if us < EXACT_BELOW_US:
        return us
    shift = us.bit_length() - _MANTISSA_BITS
    return (us >> shift) << shift


def micro_ratio(num: int, den: int) -> float:
    """``num / den`` (integers, ``den`` > 0, ``num`` >= 0) to the millionth, rounded half up in
    integer arithmetic: a decimal of at most six places, which hostc/json.c prints alike."""
    return (2 * num * 10**6 + den) // (2 * den) / 10**6


class StageStats:
    """calls, total, max and p95 of the modelled µs per call of one stage."""

    __slots__ = ("calls", "total_us", "max_us", "_counts")

    def __init__(self) -> None:
        self.calls = 0
        self.total_us = 0
        self.max_us = 0
        self._counts: dict[int, int] = {}  # bucket -> calls

    def add(self, us: int) -> None:
        """One call that took ``us`` modelled µs."""
        self.calls += 1
        self.total_us += us
        if us > self.max_us:
            self.max_us = us
        b = bucket_of(us)
        self._counts[b] = self._counts.get(b, 0) + 1

    @property
    def buckets(self) -> int:
        """Histogram buckets held (bounded: see the module docstring)."""
        return len(self._counts)

    def p95_us(self) -> int:
        """The nearest-rank 95th percentile (its bucket's value; exact below 2048 µs)."""
        if not self.calls:
            return 0
        rank = max(1, -(-95 * self.calls // 100))  # ceil(0.95 n), as stage_summary
        seen = 0
        for b in sorted(self._counts):
            seen += self._counts[b]
            if seen >= rank:
                return b
        return self.max_us  # not reached: the counts add up to calls

    def summary(self) -> dict:
        """calls, mean_us, p95_us, max_us, total_us (the keys of ``stage_summary``)."""
        if not self.calls:
            return {"calls": 0, "mean_us": 0.0, "p95_us": 0, "max_us": 0, "total_us": 0}
        return {"calls": self.calls, "mean_us": micro_ratio(self.total_us, self.calls),
                "p95_us": self.p95_us(), "max_us": self.max_us, "total_us": self.total_us}

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, StageStats):
            return NotImplemented
        return (self.calls, self.total_us, self.max_us, self._counts) == \
            (other.calls, other.total_us, other.max_us, other._counts)

    def __repr__(self) -> str:
        return f"StageStats({self.summary()})"
