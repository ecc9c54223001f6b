"""The 002 red-cylinder detector on synthetic frames (renderer-based runs: test_vision_accuracy)."""
import numpy as np
import pytest

from mobigrasp.host.vision import red_cylinder as rc

RED = (200, 30, 30)


def draw(cx, top, bottom, width, rings=(), band=2.5, extra=(), shade=1.0):
    """4x supersampled rows (the bands are horizontal), 2x columns: floor grey, a red upright
    cylinder seen side-on (a rectangle) with dark horizontal bands centred on the rows in
    ``rings``, plus extra boxes (x0, y0, x1, y1, rgb)."""
    s, sx = 4, 2
    h, w = 240, 320
    yy, xx = np.mgrid[0:h * s, 0:w * sx]
    x = (xx + 0.5) / sx - 0.5
    y = (yy + 0.5) / s - 0.5
    img = np.empty((h * s, w * sx, 3))
    img[...] = (150, 142, 128)
    img += (12 * np.sin(x / 17.0) * np.cos(y / 13.0))[..., None]
    for x0, y0, x1, y1, rgb in extra:
        img[(x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)] = rgb
    body = (abs(x - cx) <= width / 2) & (y >= top) & (y <= bottom)
    img[body] = np.array(RED) * shade
    for r in rings:
        img[body & (abs(y - r) <= band / 2)] = (20, 20, 20)
    img = img.reshape(h, s, w, sx, 3).mean(axis=(1, 3))
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("cx,r1,r2,width,shade", [
    (160.0, 100.3, 112.9, 40, 1.0), (93.6, 80.0, 125.5, 120, 0.7), (250.2, 150.1, 156.6, 22, 0.9),
])
def test_spacing_and_centre(cx, r1, r2, width, shade):
    rgb = draw(cx, r1 - 60, r2 + 60, width, rings=(r1, r2), band=max(1.2, (r2 - r1) / 5),
               shade=shade)
    res, ops = rc.detect_red_cylinder(rgb)
    assert res is not None
    assert abs(res.d_pixel_q4 / 16 - (r2 - r1)) <= 0.25
    assert abs(res.ring1_v_q4 / 16 - r1) <= 0.3 and abs(res.ring2_v_q4 / 16 - r2) <= 0.3
    assert abs(res.u_c_q4 / 16 - cx) <= 0.75
    assert abs(res.width_q4 / 16 - width) <= 1.5
    assert 0 < ops.time_us() < 33_000


def test_cut_by_the_image_border_and_red_neighbour():
    rgb = draw(120.0, -50, 300, 60, rings=(110.0, 130.0),
               extra=((150, 60, 220, 75, (230, 20, 20)), (80, 0, 100, 20, (200, 90, 30))))
    res, _ = rc.detect_red_cylinder(rgb)
    assert res is not None
    assert abs(res.d_pixel_q4 / 16 - 20.0) <= 0.25
    assert abs(res.u_c_q4 / 16 - 120.0) <= 0.75


def test_not_found_without_rings_or_without_red():
    assert rc.detect_red_cylinder(draw(160.0, 60, 200, 50))[0] is None  # red, no rings
    one = draw(160.0, 60, 200, 50, rings=(120.0,))
    assert rc.detect_red_cylinder(one)[0] is None  # one ring is not two
    orange = draw(160.0, 60, 200, 50, rings=(110.0, 125.0))
    orange[(orange[..., 0] > 150)] = (200, 100, 30)
    assert rc.detect_red_cylinder(orange)[0] is None  # orange is not red
    assert rc.detect_red_cylinder(np.full((240, 320, 3), 128, np.uint8))[0] is None


def test_red_mask_thresholds():
    px = np.array([[[200, 30, 30], [139, 64, 29], [87, 13, 13], [60, 40, 40], [255, 90, 90]]],
                  np.uint8)
    assert rc.red_mask(px).tolist() == [[1, 0, 1, 0, 1]]


def test_bad_input():
    with pytest.raises(ValueError):
        rc.detect_red_cylinder(np.zeros((240, 320), np.uint8))
    with pytest.raises(ValueError):
        rc.detect_red_cylinder(np.zeros((240, 320, 3), np.float64))


# --- the colour ROI alone (002 §2.2 step 1): what the search and the far approach use --------
def test_red_roi_is_the_stacked_red_pieces_and_their_common_columns():
    img = draw(cx=100.0, top=60.0, bottom=140.0, width=20.0, rings=(95.0, 105.0))
    res, ops = rc.detect_red_roi(img)
    assert res is not None and not res.touches_edge
    assert abs(res.u_c_q4 / 16 - 100.0) <= 1.5 and abs(res.v_c_q4 / 16 - 100.0) <= 2.0
    x, y, w, h = res.roi
    assert abs(h - 80) <= 4 and abs(w - 20) <= 4  # the rings' cuts merged into one box
    assert ops.time_us() >= rc.roi_min_ops(240, 320).time_us()
    # its range by its height: 120 mm seen 80 px tall at f = 350 px is 525 mm away
    _, _, depth_q4 = rc.roi_sighting(res, 350)
    assert abs(depth_q4 / 16 - 525) <= 30


def test_red_roi_cut_by_the_frame_gives_a_bearing_but_no_range():
    img = draw(cx=150.0, top=-10.0, bottom=140.0, width=24.0)
    res, _ = rc.detect_red_roi(img)
    assert res is not None and res.touches_edge and rc.roi_sighting(res, 350) is None


def test_no_red_no_roi():
    assert rc.detect_red_roi(draw(cx=100.0, top=60.0, bottom=140.0, width=0.0))[0] is None
    tiny = draw(cx=100.0, top=60.0, bottom=66.0, width=4.0)  # 24 px: below the ROI's size
    assert rc.detect_red_roi(tiny)[0] is None


def test_red_roi_on_rendered_views_from_any_side_up_to_3_m():
    va = pytest.importorskip("mobigrasp.tools.vision_accuracy")
    fig = va.evaluate("red_roi", frames=40, seed=20261201, empty_frames=0, degraded_frames=10)
    assert fig["detection_rate"] >= 0.99 and fig["wrong_results"] == 0, fig
    assert fig["degraded_detection_rate"] >= 0.95, fig
    assert fig["bearing_err_p95_deg"] <= 0.6, fig
