"""report.html of a run folder: the summary, the plots and the camera snapshots, linked.

``python -m mobigrasp.tools.report RUN_DIR`` (re)builds plots/ and report.html from trace.jsonl and
summary.json, so a report can be regenerated after the run.
"""

from __future__ import annotations

import html
import json
import sys
from pathlib import Path

from mobigrasp.cosim.run_folder import read_trace
from mobigrasp.tools import plots


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


def write_report(folder: Path) -> Path:
    """Write plots/*.png and report.html in ``folder``; returns the report's path."""
    folder = Path(folder)
    summary = json.loads((folder / "summary.json").read_text())
    events = read_trace(folder / "trace.jsonl") if (folder / "trace.jsonl").exists() else []
    (folder / "plots").mkdir(exist_ok=True)
    made = []
    for fn in plots.ALL:
        name = fn(events, folder / "plots")
        if name:
            made.append(name)
    frames = sorted(p.name for p in (folder / "frames").glob("*.png")) \
        if (folder / "frames").exists() else []
    ok = summary.get("success")
    title = f"{summary.get('scenario')} seed {summary.get('seed')}"
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        f"<title>mobigrasp run {html.escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:1em 2em}td{padding:1px 8px}"
        "img{max-width:100%;border:1px solid #ccc}.g{display:flex;flex-wrap:wrap;gap:8px}"
        ".g figure{margin:0}</style></head><body>",
        f"<h1>{html.escape(title)}: "
        f"<span style='color:{'green' if ok else 'red'}'>{'SUCCESS' if ok else 'FAILED'}</span>"
        "</h1>",
        f"<p>method {html.escape(str(summary.get('method')))}, transport "
        f"{html.escape(str(summary.get('transport')))}, status "
        f"{html.escape(str(summary.get('status')))}. Files: <a href='summary.json'>summary.json"
        "</a>, <a href='trace.jsonl'>trace.jsonl</a>.</p>",
    ]
    if summary.get("error"):
        parts.append(f"<p style='color:red'>error: {html.escape(summary['error'])}</p>")
    parts.append("<h2>Plots</h2><div class='g'>")
    for name in made:
        parts.append(f"<figure><a href='plots/{name}'><img src='plots/{name}'></a>"
                     f"<figcaption>{name}</figcaption></figure>")
    parts.append("</div><h2>Camera at every state change</h2><div class='g'>")
    for name in frames:
        parts.append(f"<figure><a href='frames/{name}'><img src='frames/{name}' width=320>"
                     f"</a><figcaption>{html.escape(name)}</figcaption></figure>")
    parts.append("</div><h2>Summary</h2><table>")
    parts.extend(_rows(summary))
    parts.append("</table></body></html>")
    path = folder / "report.html"
    path.write_text("\n".join(parts))
    return path


if __name__ == "__main__":
    print(write_report(Path(sys.argv[1])))
