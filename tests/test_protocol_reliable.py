import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import mobigrasp.protocol as p
from mobigrasp.protocol.reliable import DuplicateFilter, RetransmitQueue, SequenceCounter


def test_sequence_counter_wraps():
    c = SequenceCounter(254)
    assert [c.next() for _ in range(4)] == [254, 255, 0, 1]
    assert c.peek() == 2
    with pytest.raises(ValueError, match="start"):
        SequenceCounter(256)


def test_retransmit_timing_ack_and_failure():
    q = RetransmitQueue(timeout_us=20_000, max_retries=2)
    q.track(7, b"wire7", now_us=1_000)
    assert q.next_deadline_us() == 21_000
    assert q.due(20_999) == []
    assert q.due(21_000) == [b"wire7"] and q.retransmits == 1
    assert q.due(40_999) == []
    assert q.due(41_000) == [b"wire7"] and q.retransmits == 2
    assert q.due(61_000) == []  # retries used up: given up, not resent
    assert q.failed() == [7] and q.failed() == []
    assert len(q) == 0 and q.ack(7) is False
    q.track(8, b"w8", 0)
    q.track(9, b"w9", 5)
    with pytest.raises(ValueError, match="seq 8 is already waiting"):
        q.track(8, b"again", 10)
    assert q.ack(8) is True and q.ack(8) is False and q.in_flight() == [9]
    assert q.due(20_005) == [b"w9"]


def test_retransmit_rejects_bad_arguments():
    with pytest.raises(ValueError, match="timeout_us"):
        RetransmitQueue(timeout_us=0)
    with pytest.raises(ValueError, match="max_retries"):
        RetransmitQueue(max_retries=-1)
    with pytest.raises(ValueError, match="seq"):
        RetransmitQueue().track(300, b"", 0)


def test_duplicate_filter_window_and_reset():
    f = DuplicateFilter(window=3)
    got = [f.is_new(s) for s in (1, 2, 1, 3, 4, 2, 1, 2)]
    # 1 is a duplicate while among the last 3 seen; after 3 and 4 it has left the window.
    assert got == [True, True, False, True, True, False, True, True]
    assert f.duplicates == 2 and f.live_evictions == 3  # no time given: every eviction counts
    f.set_result(2, p.NACK_OUT_OF_RANGE)
    assert f.result(2) == p.NACK_OUT_OF_RANGE and f.result(4) == 0
    f.reset()
    assert f.is_new(2) and f.result(2) == 0


def test_duplicate_filter_expires_entries_so_a_wrapped_seq_is_new():
    f = DuplicateFilter(window=16, expiry_us=250_000)
    assert f.is_new(10, now_us=0)
    assert f.is_new(10, now_us=200_000) is False  # a retransmission within the span: a copy
    # 256 frames later the sender's counter is back at 10: a new command, executed.
    assert f.is_new(10, now_us=250_000) is True
    assert f.duplicates == 1 and f.live_evictions == 0
    without_time = DuplicateFilter(window=16)
    without_time.is_new(10)
    assert without_time.is_new(10) is False  # the documented hazard of omitting now_us


def test_duplicate_filter_counts_live_evictions():
    f = DuplicateFilter(window=2, expiry_us=1000)
    assert f.is_new(1, 0) and f.is_new(2, 10) and f.is_new(3, 20)
    assert f.live_evictions == 1  # seq 1 was pushed out while a copy could still come
    assert f.is_new(4, 5000) and f.live_evictions == 1  # 2 and 3 had expired
    with pytest.raises(ValueError, match="expiry_us"):
        DuplicateFilter(expiry_us=0)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 0.6), st.integers(1, 60), st.sampled_from([1, 4]))
def test_lossy_channel_executes_each_command_exactly_once(seed, loss, n_commands, window):
    """Sender with RetransmitQueue, receiver with DuplicateFilter, both directions lossy."""
    rng = random.Random(seed)
    q = RetransmitQueue(timeout_us=20_000, max_retries=10)
    dup = DuplicateFilter(window=16 if window == 1 else 64)
    seqs = SequenceCounter()
    executed: list[int] = []
    acked: set[int] = set()
    to_send = list(range(n_commands))
    in_flight: dict[int, int] = {}  # seq -> command id
    now = 0
    while to_send or len(q):
        while to_send and len(q) < window:
            cmd = to_send.pop(0)
            seq = seqs.next()
            in_flight[seq] = cmd
            q.track(seq, bytes([seq, cmd % 256]), now)
            wires = [bytes([seq, cmd % 256])]
            break
        else:
            wires = []
        wires += q.due(now)
        for wire in wires:
            if rng.random() < loss:
                continue  # command lost
            seq = wire[0]
            if dup.is_new(seq, now):
                executed.append(in_flight[seq])
            if rng.random() >= loss and q.ack(seq):  # ACK may be lost too
                acked.add(in_flight[seq])
        now += 5_000
    failed = {in_flight[s] for s in q.failed()}
    if window > 1:  # at most 1 new command per 5 ms step: 50 per expiry, a window of 64 holds them
        assert dup.live_evictions == 0
    # (Stop-and-wait needs no memory beyond the last seq: copies of a command reach the MCU
    # before the next command does, so its evictions are harmless.)
    assert len(executed) == len(set(executed))  # never twice
    assert acked | failed == set(range(n_commands)) and not acked & failed
    assert acked <= set(executed)
    if window == 1:  # stop-and-wait: execution order is sending order even under loss
        assert executed == sorted(executed)


def test_several_outstanding_commands_can_be_reordered_by_a_retransmission():
    # Why docs/protocol.md asks for one outstanding command (or cancel() of superseded ones):
    q = RetransmitQueue(timeout_us=10)
    q.track(0, b"old", 0)
    q.track(1, b"new", 0)  # "old" was lost on the wire, "new" arrived and was executed
    q.ack(1)
    assert q.due(10) == [b"old"]  # ... and now the stale command would run after it
    q.track(2, b"newer", 10)
    assert q.cancel(0) is True and q.cancel(0) is False
    assert q.due(1_000) == [b"newer"]
