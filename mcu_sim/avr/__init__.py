"""Register-level peripheral models of the ATmega128 (timers, USART, pins), in simulated time."""
