"""The per-method interface of the task (host/task/method.py): one object per method, chosen by
name, and the machine asks it wherever the methods differ."""

import inspect
from pathlib import Path

import pytest

from mobigrasp.host.task import METHODS, Method, Task, TaskInputs, TaskParams, method_rules
from mobigrasp.host.vision import registry

HOST = Path(__file__).resolve().parents[1] / "host"


@pytest.mark.parametrize("name", sorted(METHODS))
def test_each_method_implements_the_interface_and_names_registered_detectors(name):
    rules = method_rules(name)
    assert isinstance(rules, Method) and rules.name == name and rules is method_rules(name)
    assert not inspect.isabstract(type(rules))
    names = {rules.search_detector, rules.adjust_detector, *rules.check_detectors}
    for used in rules.detectors.values():
        names |= set(used)
    assert all(registry.row(n) for n in names)
    assert rules.search_detector in rules.detectors["SEARCH"]
    task = Task(name)
    assert task.rules is rules and task.cam == rules.camera
    for key, value in rules.param_defaults.items():
        assert getattr(task.p, key) == value or key == "search"
    assert task.detectors_needed() == list(rules.detectors["SEARCH"])


def test_unknown_method_is_refused_by_name():
    with pytest.raises(ValueError, match="003"):
        method_rules("003")
    with pytest.raises(ValueError, match="method"):
        TaskParams.for_method("003")


def test_the_machine_asks_the_method_object():
    # a method object with another search detector: the machine looks for what it says
    base = method_rules("000")

    class Other(type(base)):
        search_detector = "double_cross"
        detectors = {**base.detectors, "SEARCH": ("double_cross",)}

    task = Task("000")
    task.rules = Other()
    out = task.step(0, TaskInputs(detections={"radial_symbol": object()}))
    assert task.counters["bad_detections"] == 0  # the radial symbol is not looked at
    assert out.state == "SEARCH" and task.detectors_needed() == ["double_cross"]


def test_no_method_string_comparisons_in_the_host():
    for path in HOST.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        assert "method ==" not in text and "method !=" not in text, path
