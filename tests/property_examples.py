"""How many examples a property test runs: ``examples(n)`` is the settings of a test whose full
count is ``n``, scaled by the loaded Hypothesis profile (tests/conftest.py): the whole count in
a run that includes the slow tests (``make test-all``) or with ``HYPOTHESIS_PROFILE=ci``, a
share of it (the fast profile's max_examples per 100, at least FAST_FLOOR) in the fast suite
(``make test``, a bare pytest)."""

from __future__ import annotations

from hypothesis import settings

FAST_FLOOR = 10  # the fewest examples a property test runs in the fast suite


def examples(n: int, **kwargs) -> settings:
    """``settings(max_examples=...)`` for a test of ``n`` examples in the full profile (no
    deadline: the C builds and the emulated MCUs take their time on a loaded machine)."""
    share = settings().max_examples  # the loaded profile's (the full one: Hypothesis' 100)
    count = n if share >= 100 else min(n, max(FAST_FLOOR, round(n * share / 100)))
    return settings(max_examples=count, deadline=None, **kwargs)
