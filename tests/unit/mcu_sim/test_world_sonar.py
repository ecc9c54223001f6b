"""Sonar ring of paper 001 against analytic geometry, plus seeded noise and dropout."""

import math

import numpy as np
import pymunk
import pytest

from mobigrasp.mcu_sim.world.base import FOOTPRINT_RADIUS_M, DiffDriveBase, new_space
from mobigrasp.mcu_sim.world.sonar import SonarConfig, SonarRing, sensor_angles


def ring(**kw):
    return SonarRing(SonarConfig(**kw), np.random.default_rng(0))


def space_with_robot(x=0.0, y=0.0, h=0.0):
    space = new_space()
    base = DiffDriveBase(space, x, y, h)
    return space, base


def test_sensor_angles_follow_001():
    assert sensor_angles(5) == pytest.approx([-math.pi / 2, -math.pi / 4, 0.0, math.pi / 4,
                                              math.pi / 2])
    assert sensor_angles(2) == pytest.approx([-math.pi / 2, math.pi / 2])


@pytest.mark.parametrize("heading", [0.0, 1.0, -2.0])
@pytest.mark.parametrize("dist", [0.3, 1.0, 2.2])
def test_front_sensor_sees_a_perpendicular_wall_at_the_analytic_range(heading, dist):
    space, base = space_with_robot(h=heading)
    # wall perpendicular to the heading, ``dist`` ahead of the front sensor
    c, s = math.cos(heading), math.sin(heading)
    d = FOOTPRINT_RADIUS_M + dist
    mid = (d * c, d * s)
    a = (mid[0] - 5 * s, mid[1] + 5 * c)
    b = (mid[0] + 5 * s, mid[1] - 5 * c)
    space.add(pymunk.Segment(space.static_body, a, b, 0.0))
    r = ring().read(space, base.pose())
    assert r[2] == pytest.approx(dist, abs=0.01)


def test_circle_obstacle_range_and_which_sensors_see_it():
    space, base = space_with_robot()
    # circle of radius 0.2 m on the left (phi = +pi/2, sensor 5), centre 1.0 m from the robot
    space.add(pymunk.Circle(space.static_body, 0.2, (0.0, 1.0)))
    r = ring().read(space, base.pose())
    assert r[4] == pytest.approx(1.0 - 0.2 - FOOTPRINT_RADIUS_M, abs=0.01)
    assert r[0] is None and r[1] is None and r[2] is None
    # the 45-degree sensor sits at (0.12, 0.12); its cone ends at pi/4 + 0.525 = 1.31 rad but
    # the circle starts at atan2(0.88, -0.12) - asin(0.2 / 0.888) = 1.48 rad: not seen
    assert r[3] is None
    # turn the robot 20 degrees left: now the circle enters that sensor's cone
    r2 = ring().read(space, (0.0, 0.0, 0.35))
    assert r2[3] is not None and r2[3] > r[4]


def test_nothing_in_range_gives_none_and_d_e_limits_range():
    space, base = space_with_robot()
    space.add(pymunk.Circle(space.static_body, 0.1, (3.5, 0.0)))
    assert ring().read(space, base.pose()) == [None] * 5
    assert ring(D_e=4.0).read(space, base.pose())[2] == pytest.approx(3.5 - 0.1 - 0.17,
                                                                         abs=0.01)


def test_the_robot_does_not_see_itself():
    space, base = space_with_robot()
    assert ring(k_s=7).read(space, base.pose()) == [None] * 7


def test_noise_and_dropout_are_seeded_and_bounded():
    space, base = space_with_robot()
    space.add(pymunk.Segment(space.static_body, (1.17, -5), (1.17, 5), 0.0))

    def readings(seed):
        r = SonarRing(SonarConfig(noise_std_m=0.02, dropout_p=0.3), np.random.default_rng(seed))
        return [r.read(space, base.pose())[2] for _ in range(300)]

    a, b, c = readings(5), readings(5), readings(6)
    assert a == b and a != c
    got = [v for v in a if v is not None]
    assert 150 < len(got) < 270  # about 70 % survive the dropout
    assert np.mean(got) == pytest.approx(1.0, abs=0.01)
    assert np.std(got) == pytest.approx(0.02, rel=0.3)


def test_bad_config_is_rejected():
    with pytest.raises(ValueError, match="k_s"):
        SonarConfig(k_s=1)
    with pytest.raises(ValueError):
        SonarConfig(dropout_p=1.5)


def test_read_one_matches_the_ring_and_checks_its_index():
    space, base = space_with_robot(h=0.3)
    space.add(pymunk.Circle(space.static_body, 0.3, (1.0, 1.0)))
    space.add(pymunk.Segment(space.static_body, (-3, -1.0), (3, -1.0), 0.0))
    r = ring()
    all_ = r.read(space, base.pose())
    assert [r.read_one(space, base.pose(), i) for i in range(5)] == all_
    assert sum(v is not None for v in all_) >= 3
    with pytest.raises(ValueError, match="sonar index"):
        r.read_one(space, base.pose(), 5)
