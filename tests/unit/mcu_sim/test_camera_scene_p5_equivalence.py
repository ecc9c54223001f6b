"""A prism's side faces built as one array (perf round 5) are bit for bit the faces built one by
one: vertices, normals, centres, face order, colours and the packed arrays, for every target
kind, obstacle and clutter shape at many poses (a moving target is rebuilt every frame).
"""

from __future__ import annotations

import math

import numpy as np

from mobigrasp.mcu_sim.world import camera as cam
from mobigrasp.mcu_sim.world import camera_scene as cs


def _prism_face_by_face(item, foot_xy, bands, top_rgb):
    """camera_scene._prism as it was before perf round 5 (the reference)."""
    k = len(foot_xy)
    for i in range(k):
        a, b = foot_xy[i], foot_xy[(i + 1) % k]
        d = b - a
        n = np.array([d[1], -d[0], 0.0]) / math.hypot(d[0], d[1])
        for z0, z1, rgb in bands:
            quad = np.array([[a[0], a[1], z0], [b[0], b[1], z0],
                             [b[0], b[1], z1], [a[0], a[1], z1]])
            item.faces.append((quad, n, rgb))
    ztop = bands[-1][1]
    top = np.column_stack([foot_xy, np.full(k, ztop)])
    item.faces.append((top, cs._UP, top_rgb))


def _flat_face(item, foot_xy, rgb):
    poly = np.column_stack([foot_xy, np.full(len(foot_xy), 0.0005)])
    item.faces.append((poly, cs._UP, rgb))


def _items(scene):
    """The scene's items built without any cache (the reference when monkeypatched)."""
    items = []
    if scene.target is not None:
        items.extend(it.pack() for it in cs._target_items(scene.target))
    items.extend(cs._obstacle_item.__wrapped__(o) for o in scene.obstacles)
    items.extend(cs._clutter_item.__wrapped__(c) for c in scene.clutter)
    return items


def _scenes():
    rng = np.random.default_rng(11)
    for kind in cs.TARGET_KINDS:
        for _ in range(12):
            t = cs.Target(kind, float(rng.uniform(-3, 3)), float(rng.uniform(-3, 3)),
                          float(rng.uniform(-math.pi, math.pi)))
            obstacles = (cs.Obstacle("circle", float(rng.uniform(-2, 2)), 0.3,
                                     radius_m=float(rng.uniform(0.05, 0.4))),
                         cs.Obstacle("box", 1.1, float(rng.uniform(-2, 2)), width_m=0.3,
                                     depth_m=float(rng.uniform(0.1, 1.0)),
                                     heading_rad=float(rng.uniform(-3, 3))))
            clutter = tuple(cs.Clutter(shape, float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)),
                                       float(rng.uniform(0.02, 0.2)), (10, 200, 30),
                                       float(rng.uniform(-3, 3)),
                                       0.1 if shape in ("box", "cylinder") else 0.0)
                            for shape in cs.CLUTTER_SHAPES)
            yield cs.Scene(t, obstacles, clutter, seed=1)


def _same_item(got, want):
    assert np.array_equal(got.ref_w, want.ref_w)
    for name in ("verts", "starts", "normals", "centres"):
        g, w = getattr(got, name), getattr(want, name)
        assert g.dtype == w.dtype and g.shape == w.shape and np.array_equal(g, w), name
        assert g.tobytes() == w.tobytes(), name  # also the sign of every zero
    assert len(got.faces) == len(want.faces)
    for (gp, gn, grgb), (wp, wn, wrgb) in zip(got.faces, want.faces, strict=True):
        assert gp.tobytes() == wp.tobytes() and gp.shape == wp.shape
        assert gn.tobytes() == wn.tobytes() and grgb == wrgb
    assert cam._face_colours(got) == cam._face_colours(want)
    assert len(got.textures) == len(want.textures)


def test_prism_faces_built_as_one_array_equal_face_by_face(monkeypatch):
    scenes = list(_scenes())
    fast = [_items(s) for s in scenes]
    monkeypatch.setattr(cs, "_prism", _prism_face_by_face)
    monkeypatch.setattr(cs, "_flat", _flat_face)
    ref = [_items(s) for s in scenes]
    for got, want in zip(fast, ref, strict=True):
        assert len(got) == len(want)
        for g, w in zip(got, want, strict=True):
            _same_item(g, w)
            assert not w.parts and g.parts  # the reference took the face-by-face path


def test_pack_of_faces_added_directly_still_stacks_them():
    it = cs.Item(np.zeros(3))
    quad = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    it.faces.append((quad, cs._UP, (1, 2, 3)))
    it.add_face(quad + 1.0, cs._UP, (4, 5, 6))
    it.pack()
    assert it.verts.shape == (8, 3) and it.starts.tolist() == [0, 4, 8]
    assert it.centres.tolist() == [[0.5, 0.5, 0.0], [1.5, 1.5, 1.0]]


def test_quad_centre_is_the_sum_in_index_order():
    # what the vectorised centres rely on: np.add.reduce along a face's rows adds them in
    # index order (another association differs on most of these)
    rng = np.random.default_rng(4)
    for _ in range(2000):
        q = rng.standard_normal((4, 3)) * 10.0 ** rng.uniform(-3, 3) + rng.standard_normal(3)
        assert np.array_equal(np.add.reduce(q, axis=0) / 4, (((q[0] + q[1]) + q[2]) + q[3]) / 4)
