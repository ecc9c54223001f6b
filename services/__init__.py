"""The application services: a run, campaigns, recording, reports, MCAP and plots.

The CLI (``mobigrasp.tools``) parses arguments, prints and maps results to exit codes; what it
runs lives here, so campaigns, the benches and other programs run the same code. This
room sits below the CLI and above ``calib``, ``drivers`` and ``cosim`` (docs/architecture.md).
"""
