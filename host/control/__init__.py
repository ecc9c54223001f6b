"""Path following, approach adjustment and fuzzy approaching (paper 002)."""
