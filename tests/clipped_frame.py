"""A frame whose bright level clips at 255: the radial symbol 1.12 m ahead of the search camera
(0.30 m up) at camera gain 1.7, noise 3, blur 1.5 px (docs/markers.md, "Camera gain")."""

from __future__ import annotations

import numpy as np

from mobigrasp.mcu_sim.world import camera_views
from mobigrasp.mcu_sim.world.camera import CameraOptions, render


def clipped_far_frame() -> tuple[camera_views.View, np.ndarray]:
    """(view with its truth, RGB frame)."""
    v = camera_views.radial_ahead(1.10, 0.5, 1.0)
    rgb = render(v.scene, v.cam_pos_w, v.R_wc, v.intr,
                 CameraOptions(noise_std=3.0, blur_px=1.5, brightness=1.7),
                 np.random.default_rng(0))
    return v, rgb
