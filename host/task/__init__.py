"""The move-to-grasp task of the host: the state machine (machine.py), one module per state
group (search.py, approach.py, adjust.py, grasp.py) and one per paper method (method000.py,
method001.py, method002.py) behind the interface of method.py."""

from mobigrasp.host.task.machine import (
    HOME_ARM,
    STATES,
    TERMINAL,
    Task,
    TaskEvent,
    TaskInputs,
    TaskOutputs,
)
from mobigrasp.host.task.method import METHODS, REGISTRY, Method, MethodState, method_rules
from mobigrasp.host.task.params import DEFAULT_TIMEOUTS_US, TaskParams

# state -> detectors run, per method (the methods' ``detectors``; names of host/vision/registry)
DETECTORS: dict[str, dict[str, tuple[str, ...]]] = {
    name: method_rules(name).detectors for name in METHODS}

__all__ = ["DEFAULT_TIMEOUTS_US", "DETECTORS", "HOME_ARM", "METHODS", "REGISTRY", "STATES",
           "TERMINAL", "Method", "MethodState", "Task", "TaskEvent", "TaskInputs", "TaskOutputs",
           "TaskParams", "method_rules"]
