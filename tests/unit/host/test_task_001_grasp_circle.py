"""001's grasp circle (eqs. (5)-(6)) is computed for the object's grasp point as built
(``grasp_height_mm``), not for 001 §IV's h_e = 0.208 m (docs/task.md)."""

import pytest

from mobigrasp.host.planning.grasp_circle import grasp_radius
from mobigrasp.host.task import Task
from mobigrasp.host.task.method001 import planner_params_001


def test_the_grasp_circle_is_for_the_grasp_height():
    p = Task("001").p
    arm = planner_params_001(p).arm
    assert arm.h_e == pytest.approx(p.grasp_height_mm / 1000.0)
    assert p.grasp_height_mm < 100  # below the object's top, 0.10 m
    # the arm reaches 0.08 m from further out than 0.208 m: a wider circle than 001 §IV's
    assert grasp_radius(arm).l_e_m == pytest.approx(0.306, abs=0.003)
    assert grasp_radius(arm).l_e_m > grasp_radius(type(arm)()).l_e_m + 0.04
