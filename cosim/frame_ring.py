"""Camera frames through shared memory: a ring of frame slots in one memory-mapped file.

A 320x240 RGB frame is 230 kB; sent inside a GRANT over the Unix socket it is copied five times
and costs the rig ~0.4 ms a frame in the socket alone. Instead the rig writes the pixels into a
slot of a file in /dev/shm (a plain temporary file where there is none), and the GRANT names the
slot (``{"path", "offset", "nbytes"}``, docs/cosim.md); the host copies them out when it decodes the
GRANT. Stdlib only, like the codec.

Slot reuse: the writer hands out slots in turn; the caller must not let a slot come round again
before the grant that used it was decoded (cosim/hosts.SocketHost keeps at most 16 grants in flight
and the ring has 32 slots, and checks).
"""

from __future__ import annotations

import mmap
import os
from typing import Any

from mobigrasp.cosim import leftovers
from mobigrasp.cosim.lockstep import LockstepError

DEFAULT_SLOTS = 32
DEFAULT_SLOT_BYTES = 320 * 240 * 3


def _shm_dir(fallback: str | None) -> str | None:
    return "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) \
        else fallback


class FrameRing:
    """The writer's end: ``put(pixels)`` -> where the reader finds them, or None (too big)."""

    def __init__(self, slots: int = DEFAULT_SLOTS, slot_bytes: int = DEFAULT_SLOT_BYTES,
                 directory: str | None = None) -> None:
        if slots < 1 or slot_bytes < 1:
            raise ValueError(f"a frame ring needs slots and bytes, got {slots} x {slot_bytes}")
        self.slots = slots
        self.slot_bytes = slot_bytes
        fd, self.path = leftovers.temp_file("frames", _shm_dir(directory))
        try:
            os.ftruncate(fd, slots * slot_bytes)
            self._map = mmap.mmap(fd, slots * slot_bytes)
        finally:
            os.close(fd)
        self._next = 0
        self.user: list[Any] = [None] * slots  # what the caller tied to each slot (a grant)

    def next_slot(self) -> int:
        """The slot the next :meth:`put` writes (the caller checks it is free)."""
        return self._next

    def put(self, pixels: bytes, user: Any = None) -> dict | None:
        """Copy ``pixels`` into the next slot; where they are, or None if they do not fit."""
        n = len(pixels)
        if n > self.slot_bytes:
            return None
        k = self._next
        self._next = (k + 1) % self.slots
        self._map[k * self.slot_bytes:k * self.slot_bytes + n] = pixels
        self.user[k] = user
        return {"path": self.path, "offset": k * self.slot_bytes, "nbytes": n}

    def unlink(self) -> None:
        """Remove the file's name (once the reader has mapped it: both ends keep their
        mapping, and nothing is left behind if this process is killed)."""
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass
        leftovers.disown(self.path)

    def close(self) -> None:
        """Unmap and remove the file."""
        try:
            self._map.close()
        finally:
            try:
                os.unlink(self.path)
            except FileNotFoundError:
                pass
            leftovers.disown(self.path)


class FrameRingReader:
    """The reader's end: copies a frame out of the ring a GRANT names (maps each file once)."""

    def __init__(self) -> None:
        self._maps: dict[str, mmap.mmap] = {}

    def __call__(self, where: Any, nbytes: int) -> bytes:
        """The ``nbytes`` pixels at ``where`` ({"path", "offset", "nbytes"}); LockstepError when
        the reference is malformed or points outside the ring."""
        if not isinstance(where, dict):
            raise LockstepError(f"shared frame reference must be an object, got {where!r}")
        path, offset, n = where.get("path"), where.get("offset"), where.get("nbytes")
        if (not isinstance(path, str) or type(offset) is not int or type(n) is not int
                or offset < 0 or n != nbytes):
            raise LockstepError(f"bad shared frame reference {where!r} for {nbytes} bytes")
        m = self._maps.get(path)
        if m is None:
            try:
                with open(path, "rb") as f:
                    m = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
            except (OSError, ValueError) as exc:
                raise LockstepError(f"shared frame ring {path!r}: {exc}") from exc
            self._maps[path] = m
        if offset + n > len(m):
            raise LockstepError(f"shared frame at {offset}+{n} is outside the ring {path!r}")
        return m[offset:offset + n]

    def close(self) -> None:
        """Unmap every ring."""
        for m in self._maps.values():
            m.close()
        self._maps.clear()
