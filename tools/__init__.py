"""The ``mobigrasp`` command-line interface."""
