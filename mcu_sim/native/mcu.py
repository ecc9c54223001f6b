"""The native MCU backend: the emulated ATmega128 of mcu_sim.mcu with the C firmware in it.

Same event loop, same peripheral models, same public methods as :class:`Mcu`; only the program
differs: ``firmware/`` compiled for this machine (mcu_sim/native/build.py) instead of the
Python model. Same inputs at the same simulated times give the same outputs as the Python
model (tests/unit/mcu_sim/test_native_equivalence.py).
"""

from __future__ import annotations

from mobigrasp.mcu_sim.mcu import Mcu
from mobigrasp.mcu_sim.native.firmware import NativeFirmware


class NativeMcu(Mcu):
    """One emulated ATmega128 running the C firmware."""

    firmware_class = NativeFirmware
