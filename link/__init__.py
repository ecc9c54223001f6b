"""Serial links by URL: a byte transport (pty, pyserial port, in-process pair) plus the message layer on top."""
