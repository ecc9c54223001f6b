"""The avr-gcc ELF of the firmware under simavr, as an MCU backend (``--mcu simavr``)."""
