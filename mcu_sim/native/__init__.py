"""The native MCU backend: the C firmware (``firmware/``) built with this machine's gcc."""
