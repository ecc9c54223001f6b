"""``mobigrasp bench loop``: closed-loop speed over the pty and in process, and a random campaign.

Real-time factor = simulated seconds / wall seconds of paper000-exp1 (capped at ``--rtf-limit-s``
simulated seconds) over the pty (two processes) and in process, the median of ``--rtf-repeats``
runs each; the baseline measured in the same run is the strict alternation (``_lag0``: the host
is granted each quantum only when the rig is at its start), and ``speedup_*_vs_lag0`` the ratio.
The same run over the pty with the avr-gcc ELF on simavr (``--mcu simavr``) gives
``realtime_factor_pty_simavr`` and ``simavr_vs_python_pty``, its ratio to the Python model's.
The hosts of ``--rtf-hosts`` (default the C program and the ARMv4T ELF under qemu-arm) run the
same scene beside the Python host (``realtime_factor_host_<host>[_inproc]``, ratios
``host_<host>_vs_python``): the first of :data:`HOST_SCENES` whose paper method every host
has (``host_scenario``, ``host_method``), the methods passed over and why in
``host_method_reason``; with none, paper000-exp1 on the idle host program in all of them
(``host_method`` idle); ``trace_equal_hosts`` says their traces agree.
The campaign (services/loop_campaign.py) runs ``--runs`` seeded random scenarios per method
(services/random_scenarios.py), over the pty by default (``--transport``; the trace is the same over
either), and reports the figures of the acceptance bar per method (docs/cosim.md, "Random scenes
of generator v2"): it prints them as the markdown table of docs/cosim.md, writes it as loop.md
and the figure loop.png beside ``--json``, and keeps the scenes, run folders and rows in
``<json stem>-runs/`` (``--resume`` continues an interrupted campaign from them).
"""

from __future__ import annotations

import statistics
import sys
import tempfile
from pathlib import Path

from mobigrasp.services.loop_campaign import (
    CampaignInputError,
    LoopCampaign,
    markdown,
    run_campaign,
)
from mobigrasp.services.random_scenarios import DEFAULT_VERSION, GENERATORS
from mobigrasp.tools.benches import BenchInputError, json_path
from mobigrasp.tools.method_choice import add_host_option
from mobigrasp.tools.progress import Progress

NAME = "loop"
HELP = "closed-loop real-time factor (pty, inproc) and success rate of random scenarios"


def add_arguments(parser) -> None:
    """Options of the loop bench."""
    parser.add_argument("--runs", type=int, default=3,
                        help="random scenarios per method (0: the real-time factor only); "
                             "loop.md, loop.png and loop-runs/ go beside --json")
    parser.add_argument("--methods", default="000,001,002",
                        help="comma-separated methods to run (default 000,001,002)")
    parser.add_argument("--seed-base", type=int, default=1000,
                        help="seed of the first run (default 1000)")
    parser.add_argument("--jobs", type=int, default=None, help="parallel runs (default: cores)")
    parser.add_argument("--generator", default=DEFAULT_VERSION, choices=tuple(GENERATORS),
                        help="random scenario generator version (services/random_scenarios.py)")
    parser.add_argument("--transport", default="pty", choices=("pty", "inproc"),
                        help="transport of the random runs: pty (two processes, default) or "
                             "inproc; the trace is the same over either")
    parser.add_argument("--time-limit-s", type=float, default=None,
                        help="simulated seconds per random run (default: the scenario's)")
    parser.add_argument("--rtf-limit-s", type=float, default=20.0,
                        help="simulated seconds of the real-time-factor runs")
    parser.add_argument("--rtf-repeats", type=int, default=3,
                        help="runs per real-time-factor figure (the median is reported; "
                             "0: no real-time-factor runs)")
    parser.add_argument("--rtf-hosts", default="c,arm",
                        help="hosts whose real-time factor is measured beside the Python "
                             "one's, on paper000-exp1, paper001-sim1 or paper002-marker: the "
                             "first whose method they all have, else on the idle host program "
                             "(default c,arm; '' none)")
    add_host_option(parser)  # of the random runs
    parser.add_argument("--resume", action="store_true",
                        help="keep the finished rows of an interrupted campaign (the same "
                             "--json and options) and run the rest")


def progress_enabled() -> bool:
    """Progress lines on stderr when it is a terminal."""
    return sys.stderr.isatty()


def _one(opts) -> dict:
    from mobigrasp.services.run_job import execute

    summary, _ = execute(opts)
    return summary


def campaign_config(args) -> LoopCampaign:
    """The campaign of the options; BenchInputError naming a bad one."""
    try:
        return LoopCampaign(methods=tuple(m.strip() for m in args.methods.split(",")
                                          if m.strip()),
                            runs=args.runs, out=campaign_folder(json_path(args, NAME)),
                            seed_base=args.seed_base, version=args.generator,
                            transport=args.transport, time_limit_s=args.time_limit_s,
                            jobs=args.jobs, resume=args.resume, host=args.host)
    except CampaignInputError as exc:
        raise BenchInputError(str(exc)) from None


def campaign_folder(json: Path) -> Path:
    """The campaign's scenes, run folders and rows: ``<json stem>-runs`` beside the JSON."""
    return json.with_name(f"{json.stem}-runs")


def write_campaign(result: dict, json: Path) -> tuple[Path, Path]:
    """loop.md (the table and the runs that missed) and loop.png beside the JSON."""
    from mobigrasp.services.plots import loop_campaign

    json.parent.mkdir(parents=True, exist_ok=True)
    md = json.with_suffix(".md")
    md.write_text(markdown(result), encoding="utf-8")
    png = json.with_suffix(".png")
    loop_campaign(result, png)
    return md, png


def _campaign(args) -> dict:
    """The random campaign of the options: its figures (the rows are in its folder)."""
    cfg = campaign_config(args)
    display = Progress(total=cfg.runs * len(cfg.methods), desc="bench loop", unit="runs",
                       enabled=not getattr(args, "quiet", False))
    try:
        result = run_campaign(cfg, progress=display)
    except CampaignInputError as exc:
        display.close()
        raise BenchInputError(str(exc)) from None
    md, png = write_campaign(result, json_path(args, NAME))
    print(markdown(result))
    print(f"written {md} and {png}")
    return {"commit": result["commit"], "generator": cfg.version, "transport": cfg.transport,
            "campaign_folder": str(cfg.out), "campaign": result["methods"],
            # each one is listed in loop.md with its folder and the command that re-runs it
            "missed_runs": sum(not r["met_bar"] for r in result["rows"])}


def rtf_hosts(args) -> tuple[str, ...]:
    """The hosts measured beside the Python one (``--rtf-hosts``); BenchInputError naming a
    bad one."""
    from mobigrasp.services.host_programs import HOSTS

    hosts = tuple(h.strip() for h in args.rtf_hosts.split(",") if h.strip())
    for h in hosts:
        if h not in HOSTS or h == "python":
            raise BenchInputError(f"--rtf-hosts: unknown host {h!r} (c, arm or both)")
    return hosts


# the scenes the hosts' figures may run, in order: the first whose method every host has
HOST_SCENES = (("paper000-exp1", "000"), ("paper001-sim1", "001"), ("paper002-marker", "002"))


def host_scene(hosts: tuple[str, ...]) -> tuple[str, str, str | None, str]:
    """(scenario, method, the method override of the runs or None, the reason the methods
    before it were passed over) of the hosts' figures: the first of :data:`HOST_SCENES` whose
    method every host has, else paper000-exp1 on the idle host program (host/task/idle.py) in
    all of them; BenchInputError when a host cannot run at all (a tool missing)."""
    from mobigrasp.services.host_programs import HostUnavailable, resolve

    try:
        for host in hosts:
            resolve(host, "idle", "pty")
    except HostUnavailable as exc:
        raise BenchInputError(str(exc)) from None
    passed = []
    for scenario, method in HOST_SCENES:
        try:
            for host in hosts:
                resolve(host, method, "pty")
        except HostUnavailable as exc:
            if "is not in the" not in str(exc):
                raise BenchInputError(str(exc)) from None
            passed.append(str(exc))
            continue
        return scenario, method, None, "; ".join(passed)
    return HOST_SCENES[0][0], "idle", "idle", "; ".join(passed)


def _configs(hosts: tuple[str, ...]) -> list[tuple[int, str, str, str, str]]:
    """(lag, tag, transport, mcu, host) of every real-time-factor figure."""
    configs = [(lag, f"{transport}{tag}", transport, "python", "python")
               for lag, tag in ((1, ""), (0, "_lag0")) for transport in ("pty", "inproc")]
    configs.append((1, "pty_simavr", "pty", "simavr", "python"))
    if hosts:  # the hosts side by side on the same scene (host_scene)
        for host in ("python", *hosts):
            configs.append((1, f"host_{host}", "pty", "python", host))
            if host != "arm":  # qemu-arm is its own process
                configs.append((1, f"host_{host}_inproc", "inproc", "python", host))
    return configs


def realtime_factors(args) -> dict:
    """The real-time factors of paper000-exp1 over both transports at both lags, and in the
    hosts of ``--rtf-hosts`` beside the Python one."""
    from mobigrasp.services.run_job import RunOptions

    hosts = rtf_hosts(args)
    scene = host_scene(hosts) if hosts else None
    results: dict = {}
    with tempfile.TemporaryDirectory(prefix="mobigrasp-bench-") as tmp:
        folder = Path(tmp)
        sha: dict = {}
        # the baseline, measured in the same run: strict alternation (host_lag_quanta = 0), where
        # host and rig take turns at every control tick instead of overlapping. The
        # configurations take turns run by run: this machine's speed drifts by ~10 % over
        # minutes, and runs in blocks would put that drift into the ratios.
        configs = _configs(hosts)
        rows: dict = {c: [] for c in configs}
        for k in range(args.rtf_repeats):
            for lag, tag, transport, mcu, host in configs:
                hosted = tag.startswith("host_")
                s = _one(RunOptions(scenario=scene[0] if hosted else "paper000-exp1",
                                    transport=transport, out=folder / f"rtf-{tag}-{k}",
                                    progress=False, plots=False,
                                    time_limit_s=args.rtf_limit_s, host_lag_quanta=lag,
                                    mcu=mcu, host=host,
                                    host_method=scene[2] if hosted else None))
                rows[lag, tag, transport, mcu, host].append(s)
                if mcu == "python":
                    sha.setdefault("hosts" if hosted else (lag, "any"), set()).add(
                        s.get("trace_sha256"))
    for (_lag, tag, _transport, _mcu, _host), runs in rows.items():
        wall = statistics.median(r["wall_time_s"] for r in runs)
        sim_s = runs[0]["sim_time_s"]
        results[f"realtime_factor_{tag}"] = round(sim_s / wall, 3)
        results[f"realtime_factor_{tag}_runs"] = [round(r["realtime_factor"], 3) for r in runs]
        results[f"sim_s_{tag}"] = sim_s
        results[f"wall_s_{tag}"] = round(wall, 3)
        # over the pty: the SIM side blocked on the host; in process: running the host
        results[f"wall_host_s_{tag}"] = round(
            statistics.median(r.get("wall_host_s", 0.0) for r in runs), 3)
        if progress_enabled():
            print(f"  rtf {tag}: {results[f'realtime_factor_{tag}_runs']}", file=sys.stderr)
    for transport in ("pty", "inproc"):
        rtf = results[f"realtime_factor_{transport}"]
        results[f"speedup_{transport}_vs_lag0"] = round(
            rtf / results[f"realtime_factor_{transport}_lag0"], 3)
    results["simavr_vs_python_pty"] = round(
        results["realtime_factor_pty_simavr"] / results["realtime_factor_pty"], 3)
    results["trace_equal_pty_inproc"] = all(len(sha[lag, "any"]) == 1 for lag in (0, 1))
    if scene is not None:
        results["host_scenario"], results["host_method"] = scene[0], scene[1]
        results["host_method_reason"] = scene[3]
        if progress_enabled() and scene[3]:
            print(f"  hosts on {scene[0]} ({scene[1]}): {scene[3]}", file=sys.stderr)
        for host in hosts:
            results[f"host_{host}_vs_python"] = round(
                results[f"realtime_factor_host_{host}"] / results["realtime_factor_host_python"],
                3)
            if host != "arm":
                results[f"host_{host}_inproc_vs_python_inproc"] = round(
                    results[f"realtime_factor_host_{host}_inproc"]
                    / results["realtime_factor_host_python_inproc"], 3)
        results["trace_equal_hosts"] = len(sha["hosts"]) == 1
    return results


def run(args) -> dict:
    """Figures of the loop bench (keys carry units); BenchInputError for a bad option, before
    anything runs."""
    if isinstance(args.rtf_repeats, bool) or args.rtf_repeats < 0:
        raise BenchInputError(f"--rtf-repeats must be an integer >= 0, got {args.rtf_repeats}")
    if not 0 < args.rtf_limit_s <= 3600:
        raise BenchInputError(f"--rtf-limit-s must be in (0, 3600] simulated s, got "
                              f"{args.rtf_limit_s}")
    campaign_config(args)  # refuses a bad campaign option before the real-time runs
    rtf_hosts(args)
    results = realtime_factors(args) if args.rtf_repeats else {}
    if args.runs > 0:
        results.update(_campaign(args))
    return results
