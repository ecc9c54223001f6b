"""What WorldPlant.capture must return: camera.render of the world's current view (shared by the
capture tests)."""

from mobigrasp.mcu_sim.world.camera import render


def expected_frame(plant, t_us):
    """camera.render of ``plant``'s current camera pose and scene at ``t_us``, no reuse."""
    pos, R = plant.world.camera_pose_world()
    return render(plant.world.camera_scene(), pos, R, plant.intrinsics, plant.options, None,
                  t_us=t_us)
