"""Serving the simulated robot to a host program that is not mobigrasp's: the serial line on a
pty and the eye-in-hand camera over HTTP, in wall time (``mobigrasp sim``, docs/cosim.md)."""
