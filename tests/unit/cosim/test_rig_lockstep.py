"""The lockstep frame with stand-ins: codec, line timing, budget model, pty == inproc traces."""

import socket
import threading

import pytest
from rig_fakes import FakeMcu, FakePlant, FakeTask, blob_detector, build_inputs, byte_done_us

from mobigrasp.cosim import lockstep as ls
from mobigrasp.cosim.handshake import HostTraffic
from mobigrasp.cosim.hosts import InprocHost
from mobigrasp.cosim.rig import Rig, RigConfig
from mobigrasp.cosim.run_folder import TraceWriter
from mobigrasp.cosim.session import run_session
from mobigrasp.drivers.lockstep import LockstepClient, serve_stream
from mobigrasp.host.app import HostApp, HostConfig
from mobigrasp.link.registry import inproc_pair, open_transport
from mobigrasp.protocol import messages as m


def test_codec_round_trip_grant_with_frames():
    px = bytes(range(256)) * 9
    g = ls.Grant(start_us=5000, until_us=10_000, uart=((4100, 3), (4900, 17)),
                 frames=(ls.FrameBlob(7, 4000, 5000, 32, 24, 3, px[:32 * 24 * 3]),))
    back = ls.decode(ls.encode(g))
    assert back == g
    assert back.uart_bytes == 20
    d = ls.Done(until_us=10_000, writes=((5000, 9),), events=({"ev": "x", "t_us": 5000},),
                load={"a": 1.5})
    assert ls.decode(ls.encode(d)) == d
    assert ls.decode(ls.encode(ls.End(at_us=3, reason="r"))) == ls.End(3, "r")


@pytest.mark.parametrize("mutate, match", [
    (lambda b: b"XXXX" + b[4:], "magic"),
    (lambda b: b[:4] + bytes([9]) + b[5:], "kind"),
    (lambda b: b[:-1], "length"),
])
def test_codec_rejects_bad_messages(mutate, match):
    raw = ls.encode(ls.Done(until_us=1, writes=((0, 2),)))
    with pytest.raises(ls.LockstepError, match=match):
        ls.decode(mutate(raw))


def test_codec_rejects_backward_chunks_and_nan():
    raw = ls.encode(ls.Done(until_us=1, writes=((5, 2), (3, 1))))
    with pytest.raises(ls.LockstepError, match="backwards"):
        ls.decode(raw)
    with pytest.raises(ls.LockstepError, match="JSON"):
        ls.encode(ls.Done(until_us=1, load={"x": float("nan")}))


def test_read_message_reports_closed_stream():
    import io
    raw = ls.encode(ls.End(at_us=1, reason="x"))
    with pytest.raises(ls.LockstepClosed):
        ls.read_message(io.BytesIO(raw[:-2]))


def _make(port_rig, port_host, vision_cycles=4_000_000, plan_cycles=0):
    mcu, plant = FakeMcu(), FakePlant()
    rig = Rig(mcu, plant, port_rig, RigConfig(quantum_us=5000, couple_us=1000, camera_fps=15))
    task = FakeTask(plan_cycles=plan_cycles)
    app = HostApp(task, {"blob": blob_detector(vision_cycles)}, build_inputs, HostConfig())
    return rig, mcu, plant, app, task


def _run_inproc(tmp_path, **kw):
    a, b = inproc_pair("rigtest")
    rig, mcu, plant, app, task = _make(a, b, **kw)
    trace = TraceWriter(tmp_path / "trace.jsonl")
    res = run_session(rig, InprocHost(LockstepClient(app, b)), trace, time_limit_us=600_000,
                      truth=plant.truth, settle_us=50_000)
    trace.close()
    return res, trace, mcu, app, task


def test_host_bytes_reach_mcu_after_their_line_time(tmp_path):
    res, trace, mcu, app, task = _run_inproc(tmp_path)
    assert res.reason == "task_done"
    # Every chunk starts no earlier than the previous one finished (the host UART serialises)
    ends = 0
    for start, data in mcu.rx_chunks:
        assert start >= ends
        ends = byte_done_us(start, len(data) - 1)
    # The first message (HELLO) is seen only once its last byte arrived, within one coupling step
    start, data = mcu.rx_chunks[0]
    t_seen, msg = mcu.seen[0]
    assert isinstance(msg, m.Hello)
    assert byte_done_us(start, len(data) - 1) <= t_seen < byte_done_us(start, len(data) - 1) + 1000
    # and the host really drove the MCU: wheels commanded in APPROACH
    assert any(isinstance(x, m.SetWheels) and x.left_mmps == 200 for _, x in mcu.seen)


def test_budget_drops_frames_and_counts_deadline_misses(tmp_path):
    # vision 80 ms > frame period 66.7 ms: every other frame is dropped
    res, _, _, app, _ = _run_inproc(tmp_path, vision_cycles=32_000_000)
    st = res.host_stats
    assert st["frames_dropped"] >= 1
    assert st["frames_processed"] + st["frames_dropped"] + st["frames_idle"] == \
        st["frames_received"]
    # a 60 ms plan in one control step misses its deadline and skips ticks
    res2, _, _, _, _ = _run_inproc(tmp_path / "b", plan_cycles=24_000_000)
    assert res2.host_stats["deadline_misses"] >= 2
    assert res2.host_stats["ticks_skipped"] >= 1
    res3, _, _, _, _ = _run_inproc(tmp_path / "c")
    assert res3.host_stats["deadline_misses"] == 0
    assert res3.host_stats["frames_dropped"] == 0


def test_host_never_runs_beyond_grant(tmp_path):
    a, b = inproc_pair("beyond")
    rig, mcu, plant, app, task = _make(a, b, plan_cycles=24_000_000)
    client = LockstepClient(app, b)
    for _ in range(100):
        grant = rig.grant()
        done = client.serve(grant)
        assert all(grant.start_us <= t < grant.until_us for t, _ in done.writes)
        assert app.now_us == grant.until_us
        rig.complete(done)
    assert all(t < 500_000 for t in task.steps)


def _run_over_pty(tmp_path):
    master = open_transport("pty://")
    slave = open_transport(master.slave_path)
    rig, mcu, plant, app, task = _make(master, slave)
    s_rig, s_host = socket.socketpair()
    client = LockstepClient(app, slave)
    t = threading.Thread(target=serve_stream,
                         args=(client, ls.SocketReader(s_host), s_host.makefile("wb")))
    t.start()

    class SockHost:
        rfile, wfile = s_rig.makefile("rb"), s_rig.makefile("wb")

        def exchange(self, grant):
            self.wfile.write(ls.encode(grant))
            self.wfile.flush()
            return ls.read_message(self.rfile)

        submit = exchange  # answered one by one, no pipelining

        def early_wanted(self, start_us):
            return True

        def finish(self, end):
            self.wfile.write(ls.encode(end))
            self.wfile.flush()
            return ls.read_message(self.rfile)

        def close(self):
            pass

        def traffic(self):
            return HostTraffic()

    host = SockHost()
    assert isinstance(ls.read_message(host.rfile), ls.Hello)
    trace = TraceWriter(tmp_path / "trace.jsonl")
    res = run_session(rig, host, trace, time_limit_us=600_000, truth=plant.truth,
                      settle_us=50_000)
    trace.close()
    t.join(timeout=60)
    master.close()
    slave.close()
    return res, trace


def test_same_trace_over_pty_and_inproc(tmp_path):
    res_i, tr_i, *_ = _run_inproc(tmp_path / "i")
    res_p, tr_p = _run_over_pty(tmp_path / "p")
    assert res_p.reason == res_i.reason == "task_done"
    assert tr_p.lines == tr_i.lines > 10
    assert tr_p.sha256() == tr_i.sha256()
    assert (tmp_path / "i" / "trace.jsonl").read_bytes() == \
        (tmp_path / "p" / "trace.jsonl").read_bytes()


def test_lag_one_issues_each_grant_a_quantum_ahead_with_older_data(tmp_path):
    a, b = inproc_pair("lag1")
    mcu, plant = FakeMcu(), FakePlant()
    rig = Rig(mcu, plant, a, RigConfig(quantum_us=5000, couple_us=1000, camera_fps=15,
                                       host_lag_quanta=1))
    app = HostApp(FakeTask(), {"blob": blob_detector(4_000_000)}, build_inputs, HostConfig())
    client = LockstepClient(app, b)
    assert rig.grants_due() == 2  # [0, 5) and [5, 10) before the first quantum is simulated
    first, second = rig.grant(), rig.grant()
    assert (first.start_us, second.start_us) == (0, 5000)
    assert not first.frames and not second.frames  # nothing produced yet
    dones = [client.serve(first), client.serve(second)]
    frames_seen = []
    for _ in range(40):
        rig.complete(dones.pop(0))
        assert rig.grants_due() == 1
        g = rig.grant()
        # the grant starts one quantum after the rig; what it carries was produced before the
        # rig's now, i.e. at least one whole quantum before the grant starts
        assert g.start_us == rig.now_us + 5000
        assert all(t <= rig.now_us for t, _ in g.uart)
        for f in g.frames:
            assert f.arrival_us == g.start_us and f.capture_us <= rig.now_us
            assert f.arrival_us - f.capture_us >= 5000
            frames_seen.append(f.seq)
        dones.append(client.serve(g))
    assert frames_seen[:3] == [0, 1, 2]
    with pytest.raises(ValueError, match="host_lag_quanta"):
        RigConfig(host_lag_quanta=-1)
    with pytest.raises(ValueError, match="host_lag_quanta"):
        RigConfig(host_lag_quanta=True)


def test_lag_zero_and_one_each_give_the_same_trace_over_both_transports(tmp_path):
    from mobigrasp.services.run_job import RunOptions, execute

    sha = {}
    for lag in (0, 1):
        for transport in ("pty", "inproc"):
            s, _ = execute(RunOptions(scenario="paper002-marker", transport=transport,
                                      out=tmp_path / f"{lag}-{transport}", progress=False,
                                      plots=False, time_limit_s=1.0, host_lag_quanta=lag))
            assert s["status"] == "finished", s.get("error")
            sha[lag, transport] = s["trace_sha256"]
    assert sha[0, "pty"] == sha[0, "inproc"]
    assert sha[1, "pty"] == sha[1, "inproc"]
    assert sha[0, "inproc"] != sha[1, "inproc"]  # the host's input really is later


def test_lag_one_keeps_host_bytes_written_ahead_for_their_own_quantum():
    # the host serves grant k+1 (and writes its bytes to the line) before the rig has read the
    # bytes of DONE k: the rig must hand each chunk to the MCU with its own DONE
    a, b = inproc_pair("lag1-writes")
    mcu, plant = FakeMcu(), FakePlant()
    rig = Rig(mcu, plant, a, RigConfig(quantum_us=5000, couple_us=1000, camera_fps=15,
                                       host_lag_quanta=1))

    def serve(grant):
        payload = bytes([grant.start_us // 5000 % 256]) * 3
        b.write(payload)
        return ls.Done(until_us=grant.until_us, writes=((grant.start_us + 100, 3),))

    inflight = [serve(rig.grant()) for _ in range(rig.grants_due())]
    for _ in range(10):
        done = inflight.pop(0)
        inflight.append(serve(rig.grant()))  # written before this quantum's bytes are read
        rig.complete(done)
    starts = [(start, data) for start, data in mcu.rx_chunks]
    assert [data for _, data in starts] == [bytes([k]) * 3 for k in range(10)]
    assert [start for start, _ in starts] == [5000 * k + 100 for k in range(10)]
