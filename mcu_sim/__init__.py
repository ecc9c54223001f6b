"""The emulated ATmega128 and the simulated hardware around both boards."""
