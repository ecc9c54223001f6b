"""Fixed-size byte ring buffer shared by an interrupt handler (producer) and the main loop.

Preallocated at start-up (a ``uint8_t buf[N]`` plus two ``uint8_t`` indices in C); a byte that
arrives while the ring is full is dropped and counted in ``overruns``, never a crash. One slot is
kept free to tell full from empty, so a ring of N bytes holds N - 1.
"""

from __future__ import annotations


class ByteRing:
    """Single-producer single-consumer ring of ``size`` bytes (size <= 256 for 8-bit indices)."""

    def __init__(self, size: int) -> None:
        if not 2 <= size <= 256:
            raise ValueError(f"ring size must be 2..256 bytes, got {size}")
        self.size = size
        self.buf = bytearray(size)
        self.head = 0  # next write
        self.tail = 0  # next read
        self.overruns = 0

    def clear(self) -> None:
        """Empty the ring (counters kept)."""
        self.head = self.tail = 0

    def __len__(self) -> int:
        return (self.head - self.tail) % self.size

    def put(self, byte: int) -> bool:
        """ISR side: store one byte; False (and overruns += 1) when full."""
        nxt = self.head + 1
        if nxt == self.size:
            nxt = 0
        if nxt == self.tail:
            self.overruns += 1
            return False
        self.buf[self.head] = byte
        self.head = nxt
        return True

    def put_bytes(self, data: bytes) -> int:
        """``put`` for each byte of ``data`` in order (what back-to-back ISR calls do), done with
        slices; returns how many were stored, the rest counted as overruns."""
        free = self.size - 1 - len(self)
        n = len(data)
        if n > free:
            self.overruns += n - free
            n = free
        head = self.head
        first = min(n, self.size - head)
        self.buf[head:head + first] = data[:first]
        if n > first:
            self.buf[0:n - first] = data[first:n]
        self.head = (head + n) % self.size
        return n

    def take_all(self) -> bytes:
        """Main-loop side: everything buffered, oldest first (the C loop reads byte by byte)."""
        head, tail = self.head, self.tail
        if head == tail:
            return b""
        if head > tail:
            out = bytes(self.buf[tail:head])
        else:
            out = bytes(self.buf[tail:]) + bytes(self.buf[:head])
        self.tail = head
        return out
