"""``python -m mobigrasp ...``: the same CLI as the ``mobigrasp`` script."""

import sys

from mobigrasp.tools.cli import main

if __name__ == "__main__":
    sys.exit(main())
