"""Seeded, chunking-independent corruption of a UART byte stream.

:class:`UartFaults` decides for every byte of one direction of the line whether it is lost and
which of its 8 data bits flip. Each decision is drawn from a counter-based hash of (run seed,
stream name, byte index, lane), never from the order of calls, so the same seed corrupts the same
bytes whether the stream is handed over in one chunk or byte by byte. Bursts are decided by the
simulated time of each byte (``t_us`` of the chunk's first start bit + its byte times at the
configured baud rate); latency is a time offset the caller adds (:meth:`UartFaults.deliver_us`).
Nothing here reads the wall clock.
"""

from __future__ import annotations

import hashlib

import numpy as np

from mobigrasp.mcu_sim.faults.plan import FaultPlan

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)
_LANES = 9  # lane 0: drop the byte; lanes 1..8: flip data bit 0..7
_BIT_WEIGHTS = (1 << np.arange(8, dtype=np.uint8)).astype(np.uint8)


def derive_key(seed: int, stream: str) -> int:
    """A 64-bit key for one random stream of a run (stable across processes and Pythons)."""
    digest = hashlib.blake2b(f"{int(seed)}/{stream}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "little")


def _mix64(x: np.ndarray) -> np.ndarray:
    """splitmix64 finaliser, element-wise on uint64 (wrapping arithmetic)."""
    x = x + _GOLDEN
    x = (x ^ (x >> np.uint64(30))) * _M1
    x = (x ^ (x >> np.uint64(27))) * _M2
    return x ^ (x >> np.uint64(31))


def uniforms(key: int, counters: np.ndarray) -> np.ndarray:
    """Uniform floats in [0, 1) for the given counters (any int array) of stream ``key``."""
    with np.errstate(over="ignore"):
        x = _mix64(np.asarray(counters, dtype=np.uint64) ^ np.uint64(key))
        x = _mix64(x)
    return (x >> np.uint64(11)).astype(np.float64) * (1.0 / (1 << 53))


class UartFaults:
    """Bit errors, byte drops and bursts on one direction of the serial line.

    ``stream`` names the direction ("host->mcu", "mcu->host") so both get independent draws.
    """

    def __init__(self, plan: FaultPlan, seed: int, stream: str = "host->mcu",
                 baud: int = 115_200) -> None:
        if baud <= 0:
            raise ValueError(f"baud must be > 0, got {baud}")
        self.plan = plan
        self.key = derive_key(seed, stream)
        self.baud = baud
        self.bit_error_rate = plan.uart_bit_error_rate
        self.drop_rate = plan.uart_drop_rate
        self.delay_us = plan.uart_latency_us
        self.burst = plan.uart_burst
        self.byte_index = 0
        self.bytes_in = 0
        self.bytes_lost = 0
        self.bits_flipped = 0

    @property
    def active(self) -> bool:
        """True if this stream can be altered at all."""
        return bool(self.bit_error_rate or self.drop_rate or self.delay_us or self.burst)

    def deliver_us(self, t_us: int) -> int:
        """When bytes sent at ``t_us`` reach the other end's line (latency added)."""
        return t_us + self.delay_us

    def byte_start_us(self, t_us: int, n: int) -> np.ndarray:
        """Start time of each of ``n`` bytes sent back to back from ``t_us`` (8N1)."""
        return t_us + (np.arange(n, dtype=np.int64) * 10_000_000) // self.baud

    def apply(self, data: bytes, t_us: int) -> tuple[bytes, int, int]:
        """Corrupt ``data`` whose first byte starts at ``t_us``: (bytes that arrive, bytes lost,
        bits flipped in the bytes that arrive)."""
        n = len(data)
        if n == 0:
            return b"", 0, 0
        first = self.byte_index
        self.byte_index += n
        self.bytes_in += n
        if not (self.bit_error_rate or self.drop_rate or self.burst):
            return bytes(data), 0, 0
        idx = np.arange(first, first + n, dtype=np.uint64)
        lanes = idx[:, None] * np.uint64(_LANES) + np.arange(_LANES, dtype=np.uint64)[None, :]
        u = uniforms(self.key, lanes)
        lost = u[:, 0] < self.drop_rate
        if self.burst is not None:
            start = round(self.burst.start_s * 1e6)
            end = start + round(self.burst.duration_s * 1e6)
            t = self.byte_start_us(t_us, n)
            lost |= (t >= start) & (t < end)
        flips = u[:, 1:] < self.bit_error_rate
        mask = (flips.astype(np.uint8) * _BIT_WEIGHTS[None, :]).sum(axis=1).astype(np.uint8)
        arr = np.frombuffer(bytes(data), dtype=np.uint8) ^ mask
        keep = ~lost
        n_lost = int(lost.sum())
        n_flipped = int(flips[keep].sum())
        self.bytes_lost += n_lost
        self.bits_flipped += n_flipped
        return arr[keep].tobytes(), n_lost, n_flipped

    def stats(self) -> dict[str, int]:
        """Counters for the run summary."""
        return {"bytes_in": self.bytes_in, "bytes_lost": self.bytes_lost,
                "bits_flipped": self.bits_flipped}
