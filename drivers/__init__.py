"""Host drivers: what runs the host program against a time source, a camera and a serial port.

``lockstep``: simulated time granted by the rig (mobigrasp.cosim); ``realtime``: the real board's
free-running clock, OpenCV camera and serial device. Both implement mobigrasp.host.hal.
"""
