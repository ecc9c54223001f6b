"""002 from a close start (generator v3 seed 1086, the cylinder 0.3-0.5 m away): the approach
finds the cylinder cut by the bottom of the frame where the crosses place it at the grasp's
reach, backs off, reads the rings and grasps, without a contact (in process; docs/task.md
"Close starts")."""

from __future__ import annotations

import pytest


@pytest.mark.slow
def test_a_cut_cylinder_is_backed_off_from_and_grasped(close_start_done):
    events, back_offs = close_start_done("002", 1086)
    assert back_offs and back_offs[0]["back_off"]["n"] == 1
    into_adjust = [e["why"] for e in events if e.get("ev") == "state" and e["to"] == "ADJUST"]
    assert into_adjust and into_adjust[-1].startswith("red cylinder seen, d_pixel")  # its rings


@pytest.mark.slow
def test_an_oblique_board_places_the_cylinder_in_view(close_start_done):
    """v3 seed 1063: the crosses seen ~0.87 rad off the board's face. The board's plane places
    the cylinder before its face (the frontal model put it 0.2 m aside, at the post, and ADJUST
    turned away from it): ADJUST turns to it, its rings stop the base by d_pixel > T_d, and the
    grasp holds it, without a contact."""
    events, _ = close_start_done("002", 1063)
    states = [e for e in events if e.get("ev") == "state"]
    assert states[1]["to"] == "ADJUST" and states[1]["why"].startswith("crosses")
    assert states[2]["to"] == "ROUGH_GRASP" and states[2]["why"].startswith("stop rule")
