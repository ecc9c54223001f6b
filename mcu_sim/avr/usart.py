"""USART0 of the ATmega128: baud rate from UBRR/U2X, per-byte timing on the line, bounded buffers.

Baud rate (datasheet, "USART Baud Rate Registers"): ``f_osc / (16 (UBRR + 1))`` with U2X = 0 and
``f_osc / (8 (UBRR + 1))`` with U2X = 1. At 16 MHz, 115200 is not exact: U2X = 1, UBRR = 16 gives
117 647 baud (+2.1 %), U2X = 0, UBRR = 8 gives 111 111 baud (-3.5 %); ``baud_error_pct`` reports it.
One 8N1 byte is 10 bit times, i.e. ``10 x 8 (UBRR + 1)`` = 1360 cycles (85 µs) for U2X = 1,
UBRR = 16: always a whole number of cycles, so the model is exact in integer time.

Receive: bytes put on the line at a start time follow each other back to back; a byte reaches the
receiver (RXC, and the firmware's RX interrupt) only once its stop bit has arrived. The line side
holds at most ``line_capacity`` bytes not yet received (the sender's FIFO plus the OS tty buffer a
pty stands for); a host writing faster than that loses the excess, counted in ``rx_line_dropped``,
never a crash. Transmit: the firmware queues bytes while fewer than ``tx_capacity`` are waiting
(its TX ring), and each byte leaves the line 10 bit times after the previous one.
Event-driven: the times of bytes are computed arithmetically from the chunk start.
"""

from __future__ import annotations

from collections import deque

F_CPU_HZ = 16_000_000
NOMINAL_BAUD = 115_200
BITS_PER_FRAME = 10  # start + 8 data + stop


def baud_rate(ubrr: int, u2x: int, f_cpu_hz: int = F_CPU_HZ) -> float:
    """Actual baud rate for UBRR and U2X (datasheet equation)."""
    if not 0 <= ubrr <= 4095:
        raise ValueError(f"UBRR must be 0..4095 (12 bits), got {ubrr}")
    if u2x not in (0, 1):
        raise ValueError(f"U2X must be 0 or 1, got {u2x}")
    return f_cpu_hz / ((8 if u2x else 16) * (ubrr + 1))


def baud_error_pct(ubrr: int, u2x: int, nominal: int = NOMINAL_BAUD,
                   f_cpu_hz: int = F_CPU_HZ) -> float:
    """Relative error of the actual rate against ``nominal``, in percent (+2.1 for 16/U2X=1)."""
    return (baud_rate(ubrr, u2x, f_cpu_hz) / nominal - 1.0) * 100.0


class Usart:
    """USART0 line timing and buffering; times are 16 MHz CPU cycles."""

    def __init__(self, ubrr: int = 16, u2x: int = 1, tx_capacity: int = 128,
                 line_capacity: int = 4096, f_cpu_hz: int = F_CPU_HZ) -> None:
        baud_rate(ubrr, u2x, f_cpu_hz)  # validates
        if tx_capacity <= 0 or line_capacity <= 0:
            raise ValueError("tx_capacity and line_capacity must be > 0")
        self.ubrr = ubrr
        self.u2x = u2x
        self.f_cpu_hz = f_cpu_hz
        self.byte_cycles = BITS_PER_FRAME * (8 if u2x else 16) * (ubrr + 1)
        self.tx_capacity = tx_capacity
        self.line_capacity = line_capacity
        self.reset()

    def reset(self) -> None:
        """Drop everything in flight (MCU reset); counters restart at zero."""
        self.rx_queue: deque[list] = deque()  # [start_cycle, data, next_index]
        self._rx_pending = 0
        self._rx_line_free = 0
        self.tx_queue: deque[list] = deque()  # [start_cycle, data]
        self._tx_pending = 0
        self._tx_line_free = 0
        self.rx_bytes = 0
        self.rx_line_dropped = 0
        self.tx_bytes = 0

    @property
    def baud(self) -> float:
        """Actual baud rate."""
        return baud_rate(self.ubrr, self.u2x, self.f_cpu_hz)

    @property
    def error_pct(self) -> float:
        """Baud error against 115200 in percent."""
        return baud_error_pct(self.ubrr, self.u2x, NOMINAL_BAUD, self.f_cpu_hz)

    # -- receive -------------------------------------------------------------------------------
    def line_put(self, data: bytes, start_cycle: int) -> int:
        """Put ``data`` on the RX line from ``start_cycle``; returns the bytes accepted."""
        room = self.line_capacity - self._rx_pending
        if len(data) > room:
            self.rx_line_dropped += len(data) - max(room, 0)
            data = data[:max(room, 0)]
        if not data:
            return 0
        start = max(start_cycle, self._rx_line_free)
        self.rx_queue.append([start, bytes(data), 0])
        self._rx_pending += len(data)
        self._rx_line_free = start + len(data) * self.byte_cycles
        return len(data)

    def next_rx_cycle(self) -> int | None:
        """Cycle at which the next byte's stop bit arrives, or None."""
        if not self.rx_queue:
            return None
        start, _, index = self.rx_queue[0]
        return start + (index + 1) * self.byte_cycles

    def next_rx_wakeup(self, max_bytes: int) -> int | None:
        """Cycle by which the receiver must be serviced: the stop bit of the next 0x00 byte (a frame
        delimiter) or of the ``max_bytes``-th pending byte, whichever comes first; None if idle.

        Bytes before that are handed over in one batch at the next event; the firmware cannot tell
        the difference because its main loop acts only on complete frames and every event takes
        all bytes received so far."""
        seen = 0
        bc = self.byte_cycles
        for start, data, index in self.rx_queue:
            end = min(len(data), index + max_bytes - seen)
            z = data.find(0, index, end)
            if z >= 0:
                return start + (z + 1) * bc
            if end < len(data) or seen + end - index >= max_bytes:
                return start + end * bc
            seen += end - index
        if self.rx_queue:
            start, data, _ = self.rx_queue[-1]
            return start + len(data) * bc
        return None

    def rx_take_until(self, cycle: int) -> bytes:
        """Bytes whose stop bit arrived at or before ``cycle``, in order."""
        out = bytearray()
        bc = self.byte_cycles
        while self.rx_queue:
            chunk = self.rx_queue[0]
            start, data, index = chunk
            done = min(len(data), (cycle - start) // bc)
            if done <= index:
                break
            out += data[index:done]
            if done == len(data):
                self.rx_queue.popleft()
            else:
                chunk[2] = done
                break
        self._rx_pending -= len(out)
        self.rx_bytes += len(out)
        return bytes(out)

    @property
    def rx_line_pending(self) -> int:
        """Bytes on the line side not yet received."""
        return self._rx_pending

    # -- transmit ------------------------------------------------------------------------------
    def tx_free(self, cycle: int) -> int:
        """Free space in the TX ring at ``cycle`` (bytes not yet fully sent count as used)."""
        self._retire_tx(cycle)
        return self.tx_capacity - self._tx_pending

    def tx_write(self, data: bytes, cycle: int) -> bool:
        """Queue ``data`` for sending if it all fits; returns False (nothing queued) otherwise."""
        if len(data) > self.tx_free(cycle):
            return False
        start = max(cycle, self._tx_line_free)
        self.tx_queue.append([start, bytes(data)])
        self._tx_pending += len(data)
        self._tx_line_free = start + len(data) * self.byte_cycles
        return True

    def _retire_tx(self, cycle: int) -> None:
        # Count bytes already on the wire as gone from the ring, keeping them for tx_take.
        pending = 0
        bc = self.byte_cycles
        for start, data in self.tx_queue:
            done = min(len(data), max(0, (cycle - start) // bc))
            pending += len(data) - done
        self._tx_pending = pending

    def tx_take_until(self, cycle: int) -> list[tuple[int, bytes]]:
        """Bytes whose last bit left by ``cycle``: ``(cycle_of_last_bit, bytes)`` per burst."""
        if not self.tx_queue:  # most calls: the line is idle (what _retire_tx would conclude)
            self._tx_pending = 0
            return []
        out: list[tuple[int, bytes]] = []
        bc = self.byte_cycles
        while self.tx_queue:
            chunk = self.tx_queue[0]
            start, data = chunk
            done = min(len(data), (cycle - start) // bc)
            if done <= 0:
                break
            out.append((start + done * bc, data[:done]))
            self.tx_bytes += done
            if done == len(data):
                self.tx_queue.popleft()
            else:
                chunk[0] = start + done * bc
                chunk[1] = data[done:]
                break
        self._retire_tx(cycle)
        return out

    def next_tx_cycle(self) -> int | None:
        """Cycle at which the last queued byte will have left the line, or None when idle."""
        return self._tx_line_free if self.tx_queue else None
