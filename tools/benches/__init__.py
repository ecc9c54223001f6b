"""Benchmarks of ``mobigrasp bench NAME``: each module defines ``NAME``, ``HELP`` and ``run(args) -> dict``."""
