"""The C protocol code both boards run, fuzzed (services/fuzz_c.py, firmware/fuzz/): a short
seeded run of each libFuzzer target (ASan + UBSan) and of the differential run against the
Python parser finds nothing, and each of them does report a planted fault."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from mobigrasp.services import fuzz_c

pytestmark = pytest.mark.skipif(not fuzz_c.shutil.which("clang"), reason="needs clang")


def test_a_short_seeded_run_of_every_target_finds_nothing():
    out = fuzz_c.run_c(inputs=6000, seed=7, diff_inputs=1500)
    for name, target in out["targets"].items():
        assert target["inputs"] == 2000, (name, target)
        assert target["crashes"] == 0 and target["sanitizer_reports"] == 0, target
    diff = out["differential"]
    assert diff["inputs"] == 1500 and diff["frames"] > 500
    assert diff["disagreements"] == 0, diff["first_disagreement"]


BUGGY = r"""
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2 || data[0] != 0x01) return 0;
    uint8_t *copy = malloc(size);
    memcpy(copy, data, size);
    volatile uint8_t past = copy[size];  /* one byte past the end */
    (void)past;
    free(copy);
    return 0;
}
"""


def test_a_target_reading_past_its_buffer_is_reported(tmp_path):
    src = tmp_path / "buggy.c"
    src.write_text(BUGGY)
    binary = tmp_path / "buggy"
    subprocess.run(["clang", *fuzz_c.CFLAGS, str(src), "-o", str(binary)], check=True)
    got = fuzz_c.run_target(binary, 10_000, seed=1, max_len=64)
    assert got["crashes"] == 1 and got["sanitizer_reports"] >= 1
    assert "heap-buffer-overflow" in got["first_report"]
    assert bytes.fromhex(got["reproducer_hex"])[0] == 0x01


def test_the_differential_run_reports_a_parser_that_disagrees(monkeypatch):
    from mobigrasp.protocol.frame import FrameParser

    real = FrameParser.feed

    def loses_the_last(self, chunk):
        return real(self, chunk)[:-1]
    monkeypatch.setattr(FrameParser, "feed", loses_the_last)
    out = fuzz_c.differential(300, seed=3)
    assert out["disagreements"] > 0 and "Python" in out["first_disagreement"]


def test_bench_fuzz_c_writes_its_figures(tmp_path):
    path = tmp_path / "fuzz.json"
    done = subprocess.run([sys.executable, "-m", "mobigrasp", "bench", "fuzz", "--c", "--inputs",
                           "300", "--diff-inputs", "200", "--json", str(path)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    data = json.loads(path.read_text())
    assert data["inputs"] == 300 and data["crashes"] == 0 and data["sanitizer_reports"] == 0
    assert data["disagreements"] == 0 and data["differential"]["inputs"] == 200
