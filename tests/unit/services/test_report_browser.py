"""report.html in a real browser: headless Chromium loads it, every image loads, nothing is
logged to the console. `make test-all` installs Debian's chromium when it is missing."""

import re
import shutil
import subprocess

import pytest

from mobigrasp.services.report import write_report

CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync", "--no-first-run", "--enable-logging=stderr", "--v=0"]
BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")

pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(BROWSER is None, reason="chromium not installed "
                                 "(make test-all installs it)")]


def render(page, profile) -> tuple[str, list[str]]:
    """(DOM after the load event, console lines) of ``page`` in a fresh browser profile."""
    done = subprocess.run([BROWSER, *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
                           "--dump-dom", page.resolve().as_uri()],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    console = [line for line in done.stderr.splitlines() if ":CONSOLE" in line]
    return done.stdout, console


def image_counts(dom: str) -> tuple[int, int]:
    body = re.search(r"<body[^>]*>", dom).group(0)
    total = re.search(r'data-images-total="(\d+)"', body)
    failed = re.search(r'data-images-failed="(\d+)"', body)
    assert total and failed, f"the onload check did not run: {body}"
    return int(total.group(1)), int(failed.group(1))


def test_report_renders_with_every_image_and_no_console_message(short_runs, tmp_path):
    folder = short_runs["paper000-exp1"]
    report = write_report(folder)
    dom, console = render(report, tmp_path / "profile")
    total, failed = image_counts(dom)
    plots = len(list((folder / "plots").glob("*.png")))
    frames = len(list((folder / "frames").glob("*.png")))
    assert total == plots + frames and plots >= 4 and frames >= 4
    assert failed == 0
    assert console == []
    # the answer comes before the figures
    assert dom.index("grasped") < dom.index("<h2>Plots</h2>") < dom.index("<h2>Details</h2>")


def test_the_check_sees_a_missing_image_and_a_console_error(short_runs, tmp_path):
    folder = tmp_path / "run"
    shutil.copytree(short_runs["paper000-exp1"], folder)
    report = write_report(folder)
    (folder / "plots" / "joints.png").unlink()
    report.write_text(report.read_text().replace(
        "</body>", "<script>console.error('broken on purpose')</script></body>"))
    dom, console = render(report, tmp_path / "profile")
    total, failed = image_counts(dom)
    assert failed == 1 and total > 1
    assert "image did not load: plots/joints.png" in dom
    assert any("broken on purpose" in line for line in console)
