"""The host's kernels in C (the ARM920T calibration, calib/): package data."""
