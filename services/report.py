"""report.html of a run folder: the answer first, then the figures, then the details.

The page opens with the outcome (the ARM9 budget's verdict in words, grasped or not, time to
grasp, final error, contacts, the ARM9 load's maximum and the host stage nearest its budget),
then the plots and the camera at every state change, then every figure of summary.json. Paths
are relative to the run folder, so the folder can be moved or archived. A small script marks an
image that did not load.

``python -m mobigrasp.services.report RUN_DIR`` (re)builds plots/ and report.html from
trace.jsonl and summary.json, so a report can be regenerated after the run.
"""

from __future__ import annotations

import html
import json
import logging
import os
import sys
from pathlib import Path

from mobigrasp.cosim.run_folder import owned_files, read_trace, record_written
from mobigrasp.services import plots

# after load: an image that failed gets a visible note; the counts go on <body> (data-images-*)
ONLOAD_CHECK = """<script>
window.addEventListener('load', function () {
  var imgs = document.images, bad = 0;
  for (var i = 0; i < imgs.length; i++) {
    if (!(imgs[i].complete && imgs[i].naturalWidth > 0)) {
      bad++;
      var note = document.createElement('p');
      note.className = 'missing';
      note.textContent = 'image did not load: ' + imgs[i].getAttribute('src');
      imgs[i].parentNode.insertBefore(note, imgs[i]);
    }
  }
  document.body.setAttribute('data-images-total', imgs.length);
  document.body.setAttribute('data-images-failed', bad);
});
</script>"""
def _rows(d: dict, prefix: str = "") -> list[str]:
    out = []
    for k, v in d.items():
        if isinstance(v, dict):
            out.extend(_rows(v, f"{prefix}{k}."))
        elif isinstance(v, list):
            continue
        else:
            if isinstance(v, float):
                v = f"{v:.4g}"
            out.append(f"<tr><td>{html.escape(prefix + str(k))}</td>"
                       f"<td>{html.escape(str(v))}</td></tr>")
    return out

log = logging.getLogger(__name__)


def nearest_budget(summary: dict) -> tuple[str, float] | None:
    """(stage, worst-case share of its budget) of the host stage nearest its budget (the
    profiler's rule: vision stages against a frame period, control stages against 20 ms)."""
    from mobigrasp.services.profile import profile_table

    rows, first = profile_table(summary.get("stages") or {}, {})
    row = next((r for r in rows if r["stage"] == first), None)
    return (first, row["share_max"]) if row else None


def _fmt(value, unit: str = "", digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}{unit}"
    return f"{value}{unit}"


def answer(summary: dict) -> list[tuple[str, str]]:
    """The lines the report leads with: (what, value) pairs."""
    grasped = summary.get("grasped")
    stage = nearest_budget(summary)
    contacts = summary.get("contacts")
    target = summary.get("contacts_target")
    load = summary.get("arm9_load_max")
    verdict = (summary.get("budget") or {}).get("verdict")
    return [
        ("ARM9 budget", verdict or "-"),
        ("grasped", "yes" if grasped else "no"),
        ("task", f"{summary.get('task_state')} ({summary.get('end_reason')})"),
        ("time to grasp", _fmt(summary.get("time_to_grasp_s"), " s simulated")),
        ("final error", _fmt(summary.get("final_error_mm"), " mm", 1)),
        ("contacts", f"{_fmt(contacts)} ({_fmt(summary.get('contact_time_s'))} s): "
                     f"{_fmt(summary.get('contacts_obstacle'))} with obstacles and marker posts,"
                     f" {_fmt(target)} with the target; least clearance "
                     f"{_fmt(summary.get('min_clearance_m'), ' m', 3)}"),
        ("path updates", f"{_fmt(summary.get('path_updates'))}; longest stand-still "
                         f"{_fmt(summary.get('stand_still_max_s'), ' s', 1)}"),
        ("ARM9 load max", "-" if load is None else f"{100 * load:.0f} %"),
        ("stage nearest its budget",
         "-" if stage is None else f"{stage[0]} ({100 * stage[1]:.0f} % of its budget at worst)"),
        ("simulated time", _fmt(summary.get("sim_time_s"), " s", 1)),
    ]


def relative_to(folder: Path, path: str | None) -> str | None:
    """``path`` relative to the run folder (as a link from report.html sees it); None when
    it names no file (a campaign's generated scenario)."""
    if not path or not Path(path).is_file():
        return None
    try:
        return os.path.relpath(Path(path).resolve(), Path(folder).resolve())
    except ValueError:  # another drive (Windows): keep it as it is
        return path


def write_report(folder: Path) -> Path:
    """Write plots/*.png and report.html in ``folder``; returns the report's path."""
    folder = Path(folder)
    summary = json.loads((folder / "summary.json").read_text())
    events = read_trace(folder / "trace.jsonl") if (folder / "trace.jsonl").exists() else []
    (folder / "plots").mkdir(exist_ok=True)
    made = []
    listed = owned_files(folder)
    for fn in plots.ALL:
        rel = f"plots/{fn.__name__}.png"  # each plot is named after its function
        if (folder / rel).exists() and rel not in listed:
            log.warning("%s: %s is not mobigrasp's: that plot is not written", folder, rel)
            continue
        record_written(folder, rel)  # listed before it is written: a later run's to replace
        name = fn(events, folder / "plots", summary)
        if name:
            made.append(name)
    frames = sorted(p.name for p in (folder / "frames").glob("*.png")) \
        if (folder / "frames").exists() else []
    ok = summary.get("success")
    verdict = "SUCCESS" if ok else "FAILED"
    if summary.get("method") == "external":  # `sim`: a host mobigrasp did not write
        verdict = f"external host, {'grasped' if ok else 'not grasped'}"
    title = f"{summary.get('scenario')} seed {summary.get('seed')}"
    scenario_file = relative_to(folder, summary.get("scenario_file"))
    details = dict(summary)
    if scenario_file is not None:
        details["scenario_file"] = scenario_file
    files = [name for name in ("summary.json", "trace.jsonl", "trace.mcap")
             if (folder / name).exists()]
    parts = [
        "<!doctype html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>mobigrasp run {html.escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:1em 2em}td{padding:1px 8px}"
        "img{max-width:100%;border:1px solid #ccc}.g{display:flex;flex-wrap:wrap;gap:8px}"
        ".g figure{margin:0}.answer td:first-child{color:#555}.answer td{font-size:1.1em}"
        ".missing{color:red}</style></head><body>",
        f"<h1>{html.escape(title)}: "
        f"<span style='color:{'green' if ok else 'red'}'>{html.escape(verdict)}</span>"
        "</h1>",
        "<table class='answer'>",
    ]
    parts += [f"<tr><td>{html.escape(k)}</td><td>{html.escape(v)}</td></tr>"
              for k, v in answer(summary)]
    parts.append("</table>")
    if summary.get("host_traffic"):
        from mobigrasp.services.wire_traffic import traffic_lines

        parts.append("<h2>Host traffic</h2><ul>")
        parts += [f"<li>{html.escape(line)}</li>"
                  for line in traffic_lines(summary["host_traffic"])]
        parts.append("</ul>")
    if summary.get("error"):
        parts.append(f"<p style='color:red'>error: {html.escape(summary['error'])}</p>")
    parts.append("<h2>Plots</h2><div class='g'>")
    for name in made:
        parts.append(f"<figure><a href='plots/{name}'><img src='plots/{name}' alt='{name}'>"
                     f"</a><figcaption>{name}</figcaption></figure>")
    parts.append("</div><h2>Camera at every state change</h2><div class='g'>")
    for name in frames:
        parts.append(f"<figure><a href='frames/{name}'><img src='frames/{name}' width=320 "
                     f"alt='{html.escape(name)}'></a><figcaption>{html.escape(name)}"
                     "</figcaption></figure>")
    parts.append("</div><h2>Details</h2>")
    scenario_link = (f"<a href='{html.escape(scenario_file)}'>{html.escape(scenario_file)}</a>"
                     if scenario_file else html.escape(str(summary.get("scenario_file", "-"))))
    parts.append(
        f"<p>scenario {scenario_link}, method {html.escape(str(summary.get('method')))}, "
        f"transport {html.escape(str(summary.get('transport')))}, status "
        f"{html.escape(str(summary.get('status')))}. Files: "
        + ", ".join(f"<a href='{n}'>{n}</a>" for n in files)
        + " (trace.mcap opens in Foxglove: docs/outputs.md).</p><table>")
    parts.extend(_rows(details))
    parts.append("</table>")
    parts.append(ONLOAD_CHECK)
    parts.append("</body></html>")
    path = folder / "report.html"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path


if __name__ == "__main__":
    print(write_report(Path(sys.argv[1])))
