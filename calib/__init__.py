"""Calibration of the host's ARM9 cost model: a frame corpus from the shipped scenarios, the
host kernels in C (``hostc/``) built for the host and for the ARM920T, an emulator with a static
ARM9TDMI timing model, and the comparison of modelled and emulated time per stage."""
