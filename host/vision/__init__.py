"""Fixed-point marker detectors of papers 000 and 002."""
