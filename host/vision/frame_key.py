"""The pixels of a frame as an immutable ``bytes`` key, for the detectors' last-frame memos
(host/app_factory._LastFrameMemo, host/vision/dark_blobs.dark_components).

A frame that crossed the lockstep channel is ``np.frombuffer`` of the GRANT's pixel bytes
(drivers/lockstep.py): a read-only view of an immutable ``bytes`` object holding exactly
its pixels in C order, which is what ``tobytes()`` would copy. That object is the key as it
is: no 230 kB copy per detector call (two per call with both memos), and a frame handed to two
detectors in turn is the same object, which ``==`` recognises without comparing the bytes.
Host speed only: the key has the same contents either way.
"""

from __future__ import annotations

import numpy as np


def frame_bytes(a: np.ndarray) -> bytes:
    """``a.tobytes()``, or the ``bytes`` object ``a`` views when it is a C-contiguous view of
    the whole of one (same contents: a C-contiguous array's memory is its bytes in C order;
    a ``bytes`` object never changes, and numpy keeps such a view read-only)."""
    if a.flags.c_contiguous:
        base = a.base
        while isinstance(base, np.ndarray):
            base = base.base
        # a contiguous view as long as the buffer starts at its start and ends at its end
        if type(base) is bytes and len(base) == a.nbytes:
            return base
    return a.tobytes()
