"""000 from a close start (generator v3 seed 1078, the object 0.43 m from the start): the radial
symbol is only seen cut by the frame's border, the search turns toward it, backs off, looks
around again, reads it and the object is grasped, without a contact (in process; docs/task.md
"000: the back-off from a symbol cut by the frame")."""

from __future__ import annotations

import pytest


@pytest.mark.slow
def test_a_cut_symbol_is_backed_off_from_and_grasped(close_start_done):
    events, back_offs = close_start_done("000", 1078)
    assert len(back_offs) == 1 and back_offs[0]["back_off"]["n"] == 1
    cut_frames = [e for e in events if e.get("ev") == "detect"
                  and (e.get("results") or {}).get("radial_cut")]
    assert cut_frames and cut_frames[0]["t_us"] <= back_offs[0]["t_us"]
    into_approach = [e["why"] for e in events if e.get("ev") == "state" and e["to"] == "APPROACH"]
    assert into_approach and into_approach[0].startswith("radial symbol seen")
