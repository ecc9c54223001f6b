"""WorldPlant.capture reuses the clean image of an unchanged pose: frames equal camera.render."""

import numpy as np
from camera_expect import expected_frame

from mobigrasp.cosim.rig_plant import WorldPlant
from mobigrasp.mcu_sim.world.camera import CameraOptions
from mobigrasp.services.run_job import resolve_scenario


def test_frames_equal_render_with_noise_blur_and_gain_while_standing_and_moving():
    _, scenario = resolve_scenario("paper000-exp1")
    plant = WorldPlant(scenario, 3)
    plant.options = CameraOptions(noise_std=4.0, blur_px=2.5, brightness=0.8)
    frames = []
    for t_us in (0, 66_666, 133_333):  # the robot stands: same pose, new noise each time
        got = plant.capture(t_us)
        assert np.array_equal(got, expected_frame(plant, t_us))
        frames.append(got.copy())
    assert not np.array_equal(frames[0], frames[1])  # the noise is still per capture time
    got[:] = 0  # a frame handed out is the caller's: scribbling on it changes nothing here
    assert np.array_equal(plant.capture(133_333), frames[2])
    plant.set_servo_pulse_us(5, 1700)  # turn the waist: a new pose, a new clean image
    plant.step_to(400_000)
    assert np.array_equal(plant.capture(400_000), expected_frame(plant, 400_000))
    assert not np.array_equal(plant.capture(400_000), frames[2])
