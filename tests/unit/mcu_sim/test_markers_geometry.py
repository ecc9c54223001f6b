"""Marker drawings carry the papers' physical sizes (measured on the textures, not restated)."""

import math

import numpy as np

from mobigrasp.mcu_sim.world import markers as mk


def _dark(tex, level=0):
    t = tex.levels[level]
    return (t[..., :3].astype(int).mean(axis=2) < 128) & (t[..., 3] > 128)


def _centre_row(tex):
    n = tex.levels[0].shape[0]
    return n // 2, 2 * tex.half_m / n  # middle row index, metres per texel


def test_radial_symbol_outer_diameter_is_L():
    tex = mk.radial_symbol_texture()
    dark = _dark(tex)
    r, m = _centre_row(tex)
    row = dark[r]
    cols = np.flatnonzero(row)
    outer = (cols.max() - cols.min() + 1) * m
    assert abs(outer - 0.109) <= 2 * m  # L = 109 mm (000 §IV)
    # dual rings: scanning in from the left edge along the middle row: dark, light, dark
    runs = np.flatnonzero(np.diff(row[: r].astype(int)) != 0)
    assert len(runs) >= 4


def test_plus_centres_are_d_act_apart_and_spokes_fit_the_grasp_window():
    (x1, y1), (x2, y2) = mk.plus_centres_m()
    assert math.hypot(x1 - x2, y1 - y2) == 0.0473  # D_act = 47.3 mm (000 §IV)
    tex = mk.radial_symbol_texture()
    dark = _dark(tex)
    n = dark.shape[0]
    m = 2 * tex.half_m / n
    c = int(round((x1 + tex.half_m) / m - 0.5))  # column through "+" 1
    col = dark[:, c]
    mid = n // 2
    run = col[mid - 40: mid + 40]
    width = run.sum() * m  # the column through the centre runs along one arm: the span
    assert abs(width - 2 * mk.PLUS_HALF_SPAN_M) <= 3 * m
    # spoke width: 20-40 px (000 §IV) with f = 611 from 0.092 to 0.18 m above the top
    for h_m in (0.0925, 0.18):
        w_px = mk.PLUS_ARM_WIDTH_M * 611 / h_m
        assert 20 <= w_px <= 40
    # the "+" stays inside the inner ring's hole
    assert mk.D_ACT_M / 2 + mk.PLUS_HALF_SPAN_M < mk.INNER_RING_R_IN_M


def test_double_cross_spokes_have_equal_width_and_gap():
    tex = mk.double_cross_texture()
    dark = _dark(tex)
    n = dark.shape[0]
    m = 2 * tex.half_m / n
    (cx, cy), _ = mk.cross_centres_m()
    r = 0.7 * mk.CROSS_RADIUS_M
    samples = []
    for k in range(360):
        a = math.radians(k)
        x, y = cx + r * math.cos(a), cy + r * math.sin(a)
        i, j = int((tex.half_m - y) / m), int((x + tex.half_m) / m)
        samples.append(bool(dark[i, j]))
    s = np.array(samples)
    assert s.sum() == 180  # half dark: spokes as wide as the gaps
    changes = np.flatnonzero(np.diff(np.r_[s, s[0]].astype(int)) != 0)
    assert len(changes) == 8  # four spokes, four gaps
    # dark centre
    i, j = int((tex.half_m - cy) / m), int((cx + tex.half_m) / m)
    assert dark[i, j]


def test_red_cylinder_rings_are_d_apart():
    bands = mk.red_cylinder_bands()
    black = [(z0 + z1) / 2 for z0, z1, rgb in bands if rgb == mk.BLACK_RGB]
    assert len(black) == 2
    assert abs(black[1] - black[0] - 0.0145) < 1e-9  # D = 1.45 cm (002 §5)
    assert bands[0][0] == 0.0 and bands[-1][1] == mk.RED_CYL_HEIGHT_M
    assert all(a[1] == b[0] for a, b in zip(bands, bands[1:], strict=False))  # no gaps


def test_ground_texture_is_seeded_and_tiles():
    a, b, c = mk.ground_texture(1), mk.ground_texture(1), mk.ground_texture(2)
    assert a.levels[0].tobytes() == b.levels[0].tobytes()
    assert a.levels[0].tobytes() != c.levels[0].tobytes()
    t = a.levels[0][..., :3].astype(int)
    # seamless: the jump across the tile border is like the jump between neighbours inside
    inner = np.abs(np.diff(t, axis=1)).mean()
    border = np.abs(t[:, 0] - t[:, -1]).mean()
    assert border < 3 * inner + 1
