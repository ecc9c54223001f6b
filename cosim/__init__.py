"""The co-simulation room: the lockstep channel and its codec, the frame ring, the rig (the time
authority), the plant adapter, the session engine, the host ends and the run wiring.

Spec: docs/cosim.md; the rooms and arrows: docs/architecture.md.
"""
