"""Suite-wide test settings.

Hypothesis runs derandomized: the same examples on every run and every machine, so a red CI is a
real regression and never a lucky draw (DESIGN.md: determinism; tests never depend on the machine).
Explore with fresh randomness locally by `HYPOTHESIS_PROFILE=explore pytest ...`.
"""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
