import json
import subprocess
import sys

import numpy as np
import pytest

from mobigrasp.calib import corpus
from mobigrasp.services.corpus import record


@pytest.fixture(scope="module")
def small_corpus(tmp_path_factory):
    out = tmp_path_factory.mktemp("corpus")
    record(out, ["paper002-marker"], time_limit_s=2.0)
    return out


def test_corpus_holds_the_frames_and_calls_of_the_run(small_corpus):
    idx = corpus.read_index(small_corpus)
    assert idx["format"] == corpus.FORMAT
    assert [s["name"] for s in idx["scenarios"]] == ["paper002-marker"]
    assert idx["frames"], "a 2 s run of paper002-marker gives the detector frames"
    calls = corpus.calls(small_corpus, idx)
    from mobigrasp.host.vision.registry import DETECTORS

    assert calls and {c.detector for c in calls} <= set(DETECTORS)
    assert idx["scenarios"][0]["calls"] >= len(calls)  # repeats are stored once
    shas = set()
    for fr in idx["frames"]:
        img = corpus.load_frame(small_corpus, fr)
        assert img.dtype == np.uint8 and img.shape == tuple(fr["shape"])
        shas.add(fr["sha256"])
    assert len(shas) == len(idx["frames"])


def test_corpus_is_reproducible_and_rewrites_its_own_folder(small_corpus, tmp_path):
    again = tmp_path / "again"
    record(again, ["paper002-marker"], time_limit_s=2.0)
    a = json.loads((small_corpus / corpus.INDEX).read_text())
    b = json.loads((again / corpus.INDEX).read_text())
    assert a == b
    record(again, ["paper002-marker"], time_limit_s=1.0)  # a corpus may be redone
    assert len(corpus.read_index(again)["frames"]) <= len(a["frames"])


def test_a_changed_frame_is_refused(small_corpus, tmp_path):
    idx = corpus.read_index(small_corpus)
    entry = dict(idx["frames"][0], sha256="0" * 64)
    with pytest.raises(corpus.CorpusError, match="sha256"):
        corpus.load_frame(small_corpus, entry)


@pytest.mark.parametrize("setup", ["file", "foreign", "bad_index"])
def test_bad_out_or_index_exits_2_naming_it(tmp_path, setup):
    target = tmp_path / "out"
    if setup == "file":
        target.write_text("x")
    else:
        target.mkdir()
        (target / "keep.txt").write_text("mine")
        if setup == "bad_index":
            (target / corpus.INDEX).write_bytes(b"\xff\xfe")
    r = subprocess.run([sys.executable, "-m", "mobigrasp", "corpus", "--out", str(target),
                        "--scenario", "paper002-marker", "--time-limit-s", "0.5"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert str(target) in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1
    if setup != "file":
        assert (target / "keep.txt").read_text() == "mine"
