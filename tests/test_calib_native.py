"""The C kernels of hostc/ (host build) against the Python kernels, bit for bit."""

import numpy as np
import pytest

from mobigrasp.calib import corpus, native
from mobigrasp.host.vision import dark_blobs, grey


def _check_front_end(rgb):
    g, _ = grey.to_grey(rgb)
    assert np.array_equal(native.grey(rgb), g)
    m, t, _ = dark_blobs.dark_mask(g)
    m_c, t_c = native.dark_mask(g)
    assert t_c == t and np.array_equal(m_c, m)
    n, labels, stats, _ = dark_blobs.components(m)
    n_c, labels_c, stats_c = native.label(m)
    assert n_c == n
    assert np.array_equal(labels_c, labels)
    assert np.array_equal(stats_c, stats)


@pytest.mark.parametrize("seed", range(40))
def test_random_frames_match(seed):
    rng = np.random.default_rng(seed)
    h, w = (int(v) for v in rng.integers(16, 70, 2))
    rgb = rng.integers(0, 256, (h, w, 3), dtype=np.uint8)
    if seed % 2:  # two-level frames: large dark components with holes and odd borders
        rgb = (rng.random((h, w, 1)) < 0.4 + 0.01 * seed).repeat(3, axis=2) * np.uint8(200) \
            + np.uint8(30)
    _check_front_end(rgb)


@pytest.mark.parametrize("mask", [np.ones((21, 17), np.uint8), np.zeros((21, 17), np.uint8),
                                  np.eye(19, 23, dtype=np.uint8)[::-1].copy()])
def test_edge_masks_label_as_opencv(mask):
    n, labels, stats, _ = dark_blobs.components(mask)
    n_c, labels_c, stats_c = native.label(mask)
    assert n_c == n and np.array_equal(labels_c, labels) and np.array_equal(stats_c, stats)


def test_small_corpus_slice_matches(tmp_path):
    corpus.record(tmp_path, ["paper000-exp1"], time_limit_s=3.0)
    idx = corpus.read_index(tmp_path)
    assert idx["frames"]
    for fr in idx["frames"][:12]:
        _check_front_end(corpus.load_frame(tmp_path, fr))


@pytest.mark.slow
def test_whole_corpus_matches(tmp_path):
    from mobigrasp.tools.run_job import shipped_scenarios

    corpus.record(tmp_path, [p.stem for p in shipped_scenarios()])
    idx = corpus.read_index(tmp_path)
    assert len(idx["scenarios"]) == 6
    for fr in idx["frames"]:
        _check_front_end(corpus.load_frame(tmp_path, fr))
