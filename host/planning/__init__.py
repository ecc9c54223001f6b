"""Bezier path planning of papers 000 and 001."""
