"""The host's traffic on the serial line, from a run's trace: what ``sim`` reports about a host
program it did not write.

The trace's ``wire`` events (mobigrasp.cosim.serve.external_host.wire_event) hold every frame
decoded, each way, at its simulated time; ``truth`` events the base's pose. From them: the
command rate by message type, the NACKs by reason, the ACK latency (a reliable command's send
time to the MCU's ACK of its seq), the watchdog trips (Telemetry's counter: how many before the
host's first frame, and when each happened), and the wheels commanded (SET_WHEELS) against the
wheels measured from the base's motion between truth samples.
"""

from __future__ import annotations

import statistics
from collections import Counter

from mobigrasp.mcu_sim.wire_names import nack_reason_name
from mobigrasp.services.mcap_out import measured_wheels


def _ms(us: float) -> float:
    return round(us / 1000, 2)


def _wheels(events: list[dict], commands: list[tuple[int, tuple[int, int]]]) -> dict | None:
    """Commanded against measured wheel speeds over the truth intervals a command was set."""
    from mobigrasp.mcu_sim.world.base import WHEEL_TRACK_M

    if not commands:
        return None
    truth = [e for e in events if e.get("ev") == "truth" and e.get("x_m") is not None]
    pairs, k, current = [], 0, None
    for prev, cur in zip(truth, truth[1:], strict=False):
        while k < len(commands) and commands[k][0] <= prev["t_us"]:
            current = commands[k][1]
            k += 1
        measured = measured_wheels(prev, cur, WHEEL_TRACK_M)
        if current is not None and measured is not None:
            pairs.append((current, (measured["left_mmps"], measured["right_mmps"])))
    if not pairs:
        return None
    mean = [round(statistics.fmean(p[i][side] for p in pairs), 1)
            for i in (0, 1) for side in (0, 1)]
    error = statistics.fmean(abs(c[s] - m[s]) for c, m in pairs for s in (0, 1))
    return {"samples": len(pairs), "commanded_mean_mmps": mean[:2],
            "measured_mean_mmps": mean[2:], "mean_abs_error_mmps": round(error, 1)}


def host_traffic(events: list[dict]) -> dict:
    """The figures above from a trace's events (JSON-ready)."""
    wire = [e for e in events if e.get("ev") == "wire"]
    to_mcu = [e for e in wire if e.get("dir") == "to_mcu"]
    to_host = [e for e in wire if e.get("dir") == "to_host"]
    end_us = max((int(e["t_us"]) for e in events if "t_us" in e), default=0)
    first_us = int(to_mcu[0]["t_us"]) if to_mcu else None
    span_s = (end_us - first_us) / 1e6 if first_us is not None else 0.0
    by_type = Counter(e.get("msg", f"type_{e.get('msg_type')}") for e in to_mcu)
    nacks = Counter(nack_reason_name(e["fields"]["reason"]) for e in to_host
                    if e.get("msg") == "Nack")
    sent: dict[int, int] = {}
    latencies: list[int] = []
    commands: list[tuple[int, tuple[int, int]]] = []
    for e in sorted(wire, key=lambda e: int(e["t_us"])):  # stable: to_mcu before to_host
        if e.get("dir") == "to_mcu" and "fields" in e:
            sent[int(e["seq"])] = int(e["t_us"])
            if e["msg"] == "SetWheels":
                f = e["fields"]
                commands.append((int(e["t_us"]), (f["left_mmps"], f["right_mmps"])))
        elif e.get("msg") in ("Ack", "Nack"):
            t0 = sent.pop(int(e["fields"]["acked_seq"]), None)
            if t0 is not None and e["msg"] == "Ack":
                latencies.append(int(e["t_us"]) - t0)
    trips = [(int(e["t_us"]), int(e["fields"]["watchdog_trips"])) for e in to_host
             if e.get("msg") == "Telemetry"]
    trip_us = [t for (t, n), (_, before) in zip(trips[1:], trips, strict=False) if n > before]
    before_host = max((n for t, n in trips if first_us is None or t < first_us), default=0)
    return {
        "host_first_frame_s": None if first_us is None else first_us / 1e6,
        "frames_to_mcu": len(to_mcu), "frames_to_host": len(to_host),
        "undecodable_to_mcu": sum(1 for e in to_mcu if "error" in e),
        "command_rate_hz": round(len(to_mcu) / span_s, 2) if span_s > 0 else None,
        "commands_by_type": dict(sorted(by_type.items())),
        "nacks_by_reason": dict(sorted(nacks.items())),
        "ack_latency_ms": {"count": len(latencies),
                           "median": _ms(statistics.median(latencies)) if latencies else None,
                           "max": _ms(max(latencies)) if latencies else None},
        "watchdog_trips": trips[-1][1] if trips else 0,
        "watchdog_trips_before_host": before_host,
        "watchdog_trip_s": [t / 1e6 for t in trip_us],
        "wheels": _wheels(events, commands),
    }


def traffic_lines(t: dict) -> list[str]:
    """:func:`host_traffic` as a few lines for people."""
    if t["host_first_frame_s"] is None:
        return ["host traffic: the host sent nothing"]
    kinds = ", ".join(f"{k} {n}" for k, n in t["commands_by_type"].items())
    lat = t["ack_latency_ms"]
    nacks = ", ".join(f"{k} {n}" for k, n in t["nacks_by_reason"].items()) or "none"
    lines = [f"host traffic: first frame at {t['host_first_frame_s']:.3f} s; "
             f"{t['frames_to_mcu']} frames at {t['command_rate_hz']}/s ({kinds}), "
             f"{t['undecodable_to_mcu']} undecodable",
             f"NACKs: {nacks}; ACK latency: {lat['count']} ACKs, median {lat['median']} ms, "
             f"max {lat['max']} ms",
             f"watchdog trips: {t['watchdog_trips_before_host']} before the host's first "
             f"frame, {t['watchdog_trips']} in all"
             + (f" (at {', '.join(f'{s:.2f}' for s in t['watchdog_trip_s'])} s)"
                if t["watchdog_trip_s"] else "")]
    w = t["wheels"]
    if w:
        lines.append(f"wheels: commanded {w['commanded_mean_mmps'][0]}/"
                     f"{w['commanded_mean_mmps'][1]} mm/s, measured "
                     f"{w['measured_mean_mmps'][0]}/{w['measured_mean_mmps'][1]} mm/s "
                     f"(mean |error| {w['mean_abs_error_mmps']} mm/s over {w['samples']} "
                     f"samples)")
    return lines
