"""One Verdict for every judge (g1_control/report/verdict.py)."""

from g1_control.report.verdict import Verdict, figures


def test_met_counts_one_goal_or_the_judged_ones():
    assert Verdict(True).met() == 1
    assert Verdict(False, "fell").met() == 0
    assert Verdict(False, "7/10 points", count=10, successes=7).met() == 7
    v = Verdict(True, "placed 2.0 cm off", {"object_error_m": 0.02})
    assert (v.ok, v.text, v.values, v.count, v.successes) == (True, "placed 2.0 cm off", {"object_error_m": 0.02}, 1, None)
    assert Verdict(True).values == {} and Verdict(True).values is not Verdict(True).values


def test_figures_leave_out_what_was_not_measured():
    import numpy as np

    values = figures(hand_error_m=None, drift=np.float64(0.01), velocity_error_pct=3)
    assert values == {"drift": 0.01, "velocity_error_pct": 3.0}
    assert all(type(v) is float for v in values.values())
