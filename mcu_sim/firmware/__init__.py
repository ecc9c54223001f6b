"""The ATmega128 program logic, written to map one-to-one onto C."""
