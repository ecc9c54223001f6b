"""Framed binary serial protocol between the S3C2440 host and the ATmega128 (standard library only, no I/O)."""
