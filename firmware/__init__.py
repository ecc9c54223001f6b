"""The ATmega128 firmware in C, its HALs, the simavr harness and the C unit test: package data
(compiled by ``mobigrasp.mcu_sim.native`` and ``mobigrasp.mcu_sim.simavr``; ``make firmware``)."""
