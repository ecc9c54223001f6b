"""What a test of your own host program needs: robots to point it at, frames, ``expect``.

- :class:`~mobigrasp.testing.stepped_robot.SteppedRobot`: a scenario's MCU, world and camera in
  this process with the simulated clock in the test's hands (``emulated_robot(scenario,
  clock="test")`` of the pytest plugin).
- :class:`~mobigrasp.testing.served_robot.ServedRobot`: the same robot served in wall time as
  ``mobigrasp sim`` serves it, in a thread of this process (``emulated_robot(scenario)``).
- :class:`~mobigrasp.testing.bench_robot.BenchRobot`: the same interface on a real robot (a serial
  device and a camera; ``pytest --robot-port DEVICE --robot-camera INDEX|FILE``).
- :func:`~mobigrasp.testing.expect.expect`: step a clock until a condition holds, or fail with
  what was last seen.
- :mod:`~mobigrasp.testing.frames`: the camera of ``mobigrasp sim`` (``/frame.png``, the MJPEG
  stream) as numpy images.

Submodules are imported on use: this package imports nothing heavy itself.
"""
