"""report.html leads with the answer and names the scenario relative to the run folder."""

import json
import re
from pathlib import Path

from mobigrasp.services.report import answer, write_report


def test_report_leads_with_the_answer(short_runs):
    folder = short_runs["paper000-exp1"]
    summary = json.loads((folder / "summary.json").read_text())
    page = write_report(folder).read_text()
    lines = dict(answer(summary))
    assert lines["grasped"] == ("yes" if summary["grasped"] else "no")
    assert lines["time to grasp"] == f"{summary['time_to_grasp_s']:.2f} s simulated"
    assert lines["final error"] == f"{summary['final_error_mm']:.1f} mm"
    assert lines["ARM9 load max"] == f"{100 * summary['arm9_load_max']:.0f} %"
    stage = lines["stage nearest its budget"].split()[0]
    assert stage in summary["stages"]
    first_answer = page.index("<td>grasped</td>")
    assert first_answer < page.index("<img") < page.index("<h2>Details</h2>")


def test_scenario_path_is_relative_to_the_run(short_runs):
    folder = short_runs["paper001-sim1"]
    page = write_report(folder).read_text()
    link = re.search(r"scenario <a href='([^']+)'", page).group(1)
    assert not Path(link).is_absolute()
    assert (folder / link).resolve() == Path(
        json.loads((folder / "summary.json").read_text())["scenario_file"]).resolve()
    assert str(folder.resolve()) not in page  # nothing absolute about the run's own place
