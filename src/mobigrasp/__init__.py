"""mobigrasp: the embedded mobile manipulator of papers 000-002 as one installed namespace.

The repository keeps its rooms as top-level folders (``protocol/``, ``link/``, ``host/``,
``mcu_sim/``, ``tools/``); ``pyproject.toml`` maps each into this package (``package-dir``), so
they are imported as ``mobigrasp.protocol``, ``mobigrasp.host`` and so on, and nothing generic is
installed at the top level. ``docs/architecture.md`` draws the rooms and their arrows.
"""
