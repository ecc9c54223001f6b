"""The host program a test starts against ``emulated_robot`` (wall clock), as ``pytest
--robot-host python|c|arm`` chooses it (the plugin's ``host_program`` fixture): ``mobigrasp
host`` (host/), the C program of hostc/ built for this machine, or the ARMv4T ELF under
``qemu-arm -cpu ti925t``. The C programs read the camera from the raw-frame endpoint of
``mobigrasp sim`` (``--raw-frames``), the Python one from the MJPEG stream:

    robot = emulated_robot("paper000-exp1", **host_program.robot_kw)
    subprocess.run(host_program.argv(robot, "000"))
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path
from typing import Any


class HostProgram:
    """One host program's command line against a robot of ``mobigrasp sim``."""

    def __init__(self, host: str) -> None:
        from mobigrasp.services.host_programs import HOSTS, resolve

        if host not in HOSTS:
            raise ValueError(f"--robot-host must be one of {', '.join(HOSTS)}, got {host!r}")
        self.name = host
        self._dir = tempfile.TemporaryDirectory(prefix="mg-host-")  # a short AF_UNIX path
        self.raw_frames = Path(self._dir.name) / "frames.sock"
        # the C program's prefix (built first; HostUnavailable naming a missing tool)
        self._prefix = resolve(host, "idle", "pty").prefix

    @property
    def robot_kw(self) -> dict:
        """The robot's options the host needs (``emulated_robot(scenario, **robot_kw)``)."""
        return {} if self.name == "python" else {"raw_frames": self.raw_frames}

    def argv(self, robot: Any, method: str) -> list[str]:
        """The host program running ``method`` on ``robot``'s port and camera."""
        if self.name == "python":
            return [sys.executable, "-m", "mobigrasp", "host", "--port", robot.port,
                    "--camera", robot.camera_url, "--method", method]
        return [*self._prefix, "--port", robot.port, "--method", method, "--camera",
                f"unix:{self.raw_frames}"]

    def close(self) -> None:
        """Remove the socket's folder (the session removed the socket)."""
        self._dir.cleanup()
