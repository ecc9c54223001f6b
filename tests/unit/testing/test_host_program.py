"""The plugin's ``host_program`` fixture (``pytest --robot-host``): the chosen host program's
command line against an ``emulated_robot``; the C one reads the raw-frame endpoint."""

import subprocess

import pytest

from mobigrasp.testing.host_program import HostProgram


def test_the_fixture_is_the_host_of_the_option(host_program, request):
    """python (no sim option) unless ``--robot-host`` says c or arm (the raw frames)."""
    assert host_program.name == request.config.getoption("robot_host")
    assert bool(host_program.robot_kw) == (host_program.name != "python")


def test_the_c_host_program_runs_against_the_robot(emulated_robot):
    program = HostProgram("c")
    try:
        robot = emulated_robot("paper000-exp1", speed=4.0, plots=False, time_limit_s=2.0,
                               **program.robot_kw)
        argv = program.argv(robot, "idle")
        assert argv[-2:] == ["--camera", f"unix:{program.raw_frames}"]
        done = subprocess.run(argv, capture_output=True, text=True, timeout=300, check=False)
        assert done.returncode == 1  # the session's end closed the port
        assert robot.summary["camera_frames"]["raw_sent"] > 0
        assert robot.summary["line"]["bytes_from_host"] > 0
    finally:
        program.close()


def test_an_unknown_host_is_refused():
    with pytest.raises(ValueError, match="--robot-host must be one of python, c, arm"):
        HostProgram("fpga")
