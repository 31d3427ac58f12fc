"""The runs issue 2 requires: authors' profiles, closed-loop moves and full cycles."""

import pytest

from smafinger import simulate


@pytest.mark.parametrize(
    "profile",
    ["0:-25:upper,5:-40:none,10:-30:upper", "0:-25:upper,5:-55:both"],
    ids=["authors-profile-1", "authors-profile-2"],
)
def test_authors2020_profiles_run(profile):
    r = simulate("authors2020", "independent", profile, t_end_s=20.0)
    assert r.interlock_violations == 0
    segs = r.metrics["segments"]
    assert segs[0]["reached_s"] is not None  # -25 deg with the upper actuator within 5 s
    assert segs[-1]["reached_s"] is not None  # -30 (profile 1) or -55 (profile 2)


@pytest.mark.parametrize("strategy", ["independent", "cooperative"])
@pytest.mark.parametrize("target", [-25.0, -55.0])
def test_paper2010_closed_loop_moves_reach_target(strategy, target):
    r = simulate("paper2010", strategy, f"0:{target}", t_end_s=15.0)
    seg = r.metrics["segments"][0]
    assert seg["reached_s"] is not None and seg["reached_s"] < 10.0
    assert abs(r.theta_deg[-1] - target) <= 0.5
    assert r.interlock_violations == 0


@pytest.mark.parametrize("strategy", ["independent", "cooperative"])
def test_paper2010_full_cycle_finishes(strategy):
    r = simulate("paper2010", strategy, "0:-25,reach:-55,reach:-40", t_end_s=60.0)
    segs = r.metrics["segments"]
    assert len(segs) == 3
    assert all(s["reached_s"] is not None for s in segs)
    assert r.interlock_violations == 0
