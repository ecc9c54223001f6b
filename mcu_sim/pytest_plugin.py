"""pytest plugin (``pytest11`` entry point) exposing the emulated MCU to host-program tests.

The fixtures are added by the MCU work; this module must stay importable at all times because
pytest loads it for every test run of every project that installs mobigrasp.
"""
