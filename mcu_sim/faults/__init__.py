"""Fault injection: the ``[faults]`` plan, seeded injectors and the safety monitor.

``plan``: :class:`FaultPlan`, :func:`parse_faults`, :func:`parse_fault_overrides`;
``uart``: :class:`UartFaults`; ``injectors``: camera, host, MCU, motor, sonar, encoder faults and
:class:`RunFaults`; ``safety``: :class:`SafetyMonitor`. docs/faults.md describes each key.
"""

from mobigrasp.mcu_sim.faults.injectors import CameraFaults, EncoderSlip, RunFaults
from mobigrasp.mcu_sim.faults.plan import (
    FAULT_KEYS,
    FaultError,
    FaultPlan,
    MotorFail,
    SonarFail,
    Window,
    parse_fault_overrides,
    parse_faults,
)
from mobigrasp.mcu_sim.faults.safety import SafetyMonitor
from mobigrasp.mcu_sim.faults.uart import UartFaults, derive_key

__all__ = [
    "FAULT_KEYS", "CameraFaults", "EncoderSlip", "FaultError", "FaultPlan", "MotorFail",
    "RunFaults", "SafetyMonitor", "SonarFail", "UartFaults", "Window", "derive_key",
    "parse_fault_overrides", "parse_faults",
]
