"""Subcommands of ``mobigrasp``: each module defines ``register(subparsers)``."""
