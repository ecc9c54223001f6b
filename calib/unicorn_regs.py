"""Capstone ARM register ids -> unicorn ARM register ids (by name: the two number them apart)."""

from __future__ import annotations

from functools import cache


@cache
def uc_reg(cs_reg: int) -> int:
    """The unicorn id of capstone's ARM register ``cs_reg``."""
    import capstone
    from unicorn import arm_const

    cs = capstone.Cs(capstone.CS_ARCH_ARM, capstone.CS_MODE_ARM)
    name = cs.reg_name(cs_reg).upper()
    alias = {"SB": "R9", "SL": "R10", "FP": "R11", "IP": "R12"}.get(name, name)
    return getattr(arm_const, f"UC_ARM_REG_{alias}")
