"""Where the package keeps its data, found with importlib.resources (never from a module's path).

The shipped scenarios (``mobigrasp.scenarios``), the C sources of the firmware and its harnesses
(``mobigrasp.firmware``), the host in C (``mobigrasp.hostc_sources``) and the golden protocol
vectors (``mobigrasp.protocol``) are package data: the same names work in a clone (the editable
install) and in an installed wheel. They must be files on disk (the C compilers read them), so a
zipped install is refused with the package named.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path


def data_dir(package: str) -> Path:
    """The folder of ``package`` on disk, e.g. ``data_dir("mobigrasp.firmware")``."""
    root = files(package)
    if not isinstance(root, Path) or not root.is_dir():
        raise FileNotFoundError(f"{package}: its data is not a folder on disk ({root})")
    return root
