"""Subcommands of ``mobigrasp``: each module defines ``register(subparsers)``; the CLI discovers them."""
