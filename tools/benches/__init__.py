"""Benchmarks of ``mobigrasp bench NAME``: each module has NAME, HELP and run(args) -> dict."""
