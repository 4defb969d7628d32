"""The paper's figures as numbers (sec. 6): the limits its text states, on the curves that
``python -m pyhost paper`` plots (fast path)."""
import numpy as np
import pytest

from plugins.heat import Pair
from pyhost.commands.paper import series


@pytest.fixture(scope="module")
def curves():
    return series(np.geomspace(1e-3, 1e4, 300))


def at(s, key, v0):
    return float(np.interp(np.log(v0), np.log(s["v0"]), s[key]))


def test_r2_r3_tend_to_b1_over_b2(curves):
    # eqs. (41), (42): r2, r3 -> b1/b2 = 0.393; at 20 m/s (the plot's end) within 2e-4
    limit = 1.1 / 2.8
    for key in ("r2", "r3"):
        assert at(curves, key, 20.0) == pytest.approx(limit, abs=2e-4)
        assert at(curves, key, 1e4) == pytest.approx(limit, abs=1e-6)
    # r2 comes from above, as eq. (41) says. r3 comes from below: eq. (42) assumes one
    # delta_max for both models, but B's own delta_max is smaller (r1 < 1)
    assert at(curves, "r2", 0.05) > at(curves, "r2", 1.0) > at(curves, "r2", 20.0) > limit
    assert at(curves, "r3", 0.05) < at(curves, "r3", 1.0) < at(curves, "r3", 20.0) < limit


def test_r1_r4_tend_to_one(curves):
    # Fig. 4 / Fig. 9: r1 = delta_max(B)/delta_max(A) -> 1 and r4 = t_r(A)/t_r(B) -> 1
    for key in ("r1", "r4"):
        dev = [abs(at(curves, key, v) - 1) for v in (0.1, 1.0, 20.0, 1e4)]
        assert dev == sorted(dev, reverse=True)
        assert dev[2] < 1e-3 and dev[3] < 1e-5


def test_model_B_compression_duration_flat(curves):
    t = curves["t_max_B"]
    assert np.ptp(t) / t.mean() < 1e-9


def test_heat_prefactor_meets_eqs_31_and_33(curves):
    # elastic: 0.87 (eq. 31, 0.8709 exactly); high speed: all models near 0.88 (eq. 33)
    assert at(curves, "kappa_A", 1e-3) == pytest.approx(0.8709, abs=1e-4)
    for m in "ABC":
        assert at(curves, f"kappa_{m}", 20.0) == pytest.approx(0.88, abs=3e-3)


def test_A_and_C_same_heat_different_restitution(curves):
    assert np.allclose(curves["Q_A"], curves["Q_C"], rtol=1e-12)
    assert np.all(curves["e_C"][curves["v0"] > 0.01] > curves["e_A"][curves["v0"] > 0.01])


def test_unphysical_ranges_where_the_paper_models_leave_physics(curves):
    v, v_y = curves["v0"], Pair().v_y
    B_bad = v[curves["flags_B"] != 0]
    assert B_bad.min() == v[0] and 0.15 < B_bad.max() < 0.25       # B: below about 0.2 m/s
    C_bad = v[curves["flags_C"] != 0]
    assert v_y < C_bad.min() < 1.1 * v_y and C_bad.max() < 0.1
