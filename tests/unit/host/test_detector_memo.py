"""The factory's detectors answer a repeated call (same pixels, same arguments) from memory
(host.app_factory._LastFrameMemo): exactly what the detector computes, counts included."""

from __future__ import annotations

import numpy as np

from mobigrasp.host.app_factory import _LastFrameMemo, build_host_app
from mobigrasp.host.budget import OpCounts
from mobigrasp.host.vision.dual_plus import detect_dual_plus
from mobigrasp.host.vision.radial_symbol import detect_radial_symbol
from mobigrasp.host.vision.red_cylinder import detect_red_cylinder


class _Counting:
    """A fake detector: its result names the call that computed it."""

    def __init__(self) -> None:
        self.calls = 0

    def __call__(self, rgb, *args):
        self.calls += 1
        return (self.calls, args), OpCounts(alu=int(rgb.sum()) + 1, divs=len(args))


def test_same_pixels_and_arguments_are_answered_from_memory():
    det = _Counting()
    memo = _LastFrameMemo(det)
    a = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    r1, o1 = memo(a, 5)
    r2, o2 = memo(a.copy(), 5)  # another array with the same pixels
    assert det.calls == 1 and r2 == r1 == (1, (5,))
    assert o2 == o1 and o2 is not o1  # the caller gets its own counts to add to
    o2.alu += 100
    assert memo(a, 5)[1] == o1  # what a caller does with its counts does not reach the memo


def test_anything_different_is_computed_again():
    det = _Counting()
    memo = _LastFrameMemo(det)
    a = np.zeros((2, 3, 3), np.uint8)
    memo(a, 5)
    b = a.copy()
    b[1, 2, 0] = 1
    assert memo(b, 5)[0] == (2, (5,))  # one pixel
    assert memo(b, 6)[0] == (3, (6,))  # the pose argument
    assert memo(b.reshape(3, 2, 3), 6)[0][0] == 4  # same bytes, other shape
    assert memo(b.view(np.int8), 6)[0][0] == 5  # same bytes, other dtype
    assert memo(b, 6)[0][0] == 6  # only the last call is remembered
    assert memo(b, 6)[0][0] == 6


def test_not_an_array_goes_to_the_detector():
    memo = _LastFrameMemo(lambda rgb: (rgb, OpCounts()))
    assert memo(None)[0] is None and memo([1])[0] == [1]


def _scene_frame(seed: int) -> np.ndarray:
    """A frame with dark print (a thick ring and two "+") and red on a light, noisy card:
    every detector of 000 and the red cylinder find something in it."""
    rng = np.random.default_rng(seed)
    img = rng.integers(180, 230, (240, 320, 3), dtype=np.uint8)
    yy, xx = np.indices((240, 320))
    r2 = (yy - 120) ** 2 + ((xx - 140) * 2 // 3) ** 2
    img[(r2 >= 20 ** 2) & (r2 < 30 ** 2)] = 20
    img[60:64, 230:250] = 25
    img[52:72, 238:242] = 25
    img[60:64, 195:215] = 25
    img[52:72, 203:207] = 25
    img[150:210, 250:280] = (200, 30, 30)
    img[170:174, 250:280] = 10
    img[185:189, 250:280] = 10
    return img


def test_factory_detectors_give_what_the_detectors_give_on_repeats():
    for method, names in (("000", ("dual_plus", "radial_symbol", "spoke")),
                          ("002", ("double_cross", "red_cylinder"))):
        app = build_host_app({"method": method})
        for seed in (1, 2):
            rgb = _scene_frame(seed)
            for name in names:
                det = app.detectors[name]
                snap = det.snapshot() if hasattr(det, "snapshot") else ()
                first = det(rgb, *snap)
                again = det(rgb.copy(), *snap)
                assert first[0] is not None or name == "double_cross", name  # not only misses
                assert again[0] == first[0] and again[1] == first[1], (method, name)
    # and they are the plain detectors' answers
    app = build_host_app({"method": "000"})
    rgb = _scene_frame(3)
    for _ in range(2):
        assert app.detectors["radial_symbol"](rgb) == detect_radial_symbol(rgb)
        q = app.detectors["dual_plus"].snapshot()
        assert app.detectors["dual_plus"](rgb, *q) == detect_dual_plus(
            rgb, alpha_mrad=q[0][2] + q[0][3] + q[0][4])
    app = build_host_app({"method": "002"})
    for _ in range(2):
        assert app.detectors["red_cylinder"](rgb) == detect_red_cylinder(rgb)
