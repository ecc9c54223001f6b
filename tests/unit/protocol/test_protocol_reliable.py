import random

import pytest
from hypothesis import given
from hypothesis import strategies as st
from property_examples import examples

import mobigrasp.protocol as p
from mobigrasp.protocol.reliable import (
    DUP_COPY,
    DUP_NEW,
    DUP_REUSED,
    DuplicateFilter,
    RetransmitQueue,
    SequenceCounter,
)


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


def test_duplicate_filter_copy_reuse_and_reset():
    f = DuplicateFilter(window=4)
    f.observe(1)
    assert f.classify(1, 0xAAAA) == DUP_NEW
    f.remember(1, 0xAAAA, p.NACK_OUT_OF_RANGE)
    f.observe(1)
    assert f.classify(1, 0xAAAA) == DUP_COPY and f.result(1) == p.NACK_OUT_OF_RANGE
    assert f.classify(1, 0xBBBB) == DUP_REUSED
    assert f.result(1) == p.NACK_OUT_OF_RANGE  # the slot keeps the first command
    assert (f.duplicates, f.reused) == (1, 1)
    f.reset()
    f.observe(1)
    assert f.classify(1, 0xAAAA) == DUP_NEW and f.result(1) == 0


def test_duplicate_filter_window_is_counted_in_sequence_numbers():
    f = DuplicateFilter(window=4)
    f.observe(10)
    f.remember(10, 1, 0)
    for seq in (11, 12, 13):  # 10 is 3 behind the newest: still recent
        f.observe(seq)
    assert f.classify(10, 1) == DUP_COPY
    f.observe(14)  # 4 behind: out of the window, its slot cleared
    assert f.classify(10, 1) == DUP_NEW


def test_duplicate_filter_a_copy_behind_the_newest_does_not_move_it():
    f = DuplicateFilter(window=64)
    f.observe(200)
    f.remember(200, 7, 0)
    f.observe(250)
    f.observe(200)  # the copy, 50 behind
    assert f.newest == 250 and f.classify(200, 7) == DUP_COPY
    f.observe(4)  # 10 ahead across the wrap
    assert f.newest == 4 and f.classify(200, 7) == DUP_COPY  # 60 behind
    f.observe(8)  # 64 behind: gone
    assert f.classify(200, 7) == DUP_NEW


def test_duplicate_filter_rejects_a_bad_window():
    for bad in (0, 3, 256, True, 64.0):
        with pytest.raises(ValueError, match="window"):
            DuplicateFilter(window=bad)


@examples(60)
@given(st.integers(0, 2**32 - 1), st.floats(0.0, 0.6), st.integers(1, 60), st.sampled_from([1, 4]))
def test_lossy_channel_executes_each_command_exactly_once(seed, loss, n_commands, window):
    """Sender with RetransmitQueue, receiver with DuplicateFilter, both directions lossy."""
    rng = random.Random(seed)
    q = RetransmitQueue(timeout_us=20_000, max_retries=10)
    dup = DuplicateFilter(window=64)
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
            dup.observe(seq)
            if dup.classify(seq, wire[1]) == DUP_NEW:
                dup.remember(seq, wire[1], 0)
                executed.append(in_flight[seq])
            if rng.random() >= loss and q.ack(seq):  # ACK may be lost too
                acked.add(in_flight[seq])
        now += 5_000
    failed = {in_flight[s] for s in q.failed()}
    assert dup.reused == 0
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
