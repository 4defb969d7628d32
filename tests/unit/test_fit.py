"""The fitted relations (plugins.heat.fit): stated error bounds on a fresh random sample
not used in fitting, exact limits, clipping, and the classical forms' own limits."""
import math

import numpy as np
import pytest

from plugins.heat import Pair, collide
from plugins.heat import fit as F
from plugins.heat.fit import ERROR_BOUND, collide_fit

SEED_NOT_IN_FIT = 7        # the constants were fitted on seed 2014


def fresh_sample(n, seed):
    """n random pairs (materials, sizes, walls) and speeds, v0/v_y log-uniform in
    [1e-2, 1e5], within the stated validity range."""
    rng = np.random.default_rng(seed)
    logu = lambda lo, hi: float(np.exp(rng.uniform(math.log(lo), math.log(hi))))
    out = []
    for _ in range(n):
        b1 = float(rng.uniform(1.0, 1.2))
        kw = dict(R1=logu(1e-4, 1e-2), rho1=logu(1e3, 2e4), Estar=logu(1e9, 3e11), Y=logu(1e7, 1e9),
                  b1=b1, b2=b1 * logu(1.4, 4.0), dT=float(rng.uniform(-50, 300)) or 1.0)
        pair = Pair.wall(**kw) if rng.random() < 0.2 else Pair(R2=logu(1e-4, 1e-2), **kw)
        out.append((pair, logu(1e-2, 1e5) * pair.v_y))
    return out


@pytest.mark.parametrize("model", "ABC")
def test_stated_error_bounds_hold_on_fresh_sample(model):
    worst = {q: 0.0 for q in F.QUANTITIES}
    for pair, v0 in fresh_sample(120, SEED_NOT_IN_FIT):
        ref = collide(v0, pair, model, rtol=1e-10)
        got = collide_fit(np.array([v0]), pair, model)
        for q in ("t_coll", "Q"):
            worst[q] = max(worst[q], abs(got[q][0] / getattr(ref, q) - 1))
        if ref.physical:
            worst["e"] = max(worst["e"], abs(got["e"][0] / ref.e - 1))
    for q in F.QUANTITIES:
        assert worst[q] <= ERROR_BOUND[(model, q)], (model, q, worst[q])


def test_e_never_above_one_and_elastic_range_is_hertz():
    pair = Pair()
    v = pair.v_y * np.geomspace(1e-3, 1e5, 400)
    for m in "ABC":
        assert np.all(collide_fit(v, pair, m)["e"] <= 1.0)
    slow = collide_fit(np.array([0.3 * pair.v_y]), pair, "A")
    ref = collide(0.3 * pair.v_y, pair, "A")
    assert slow["e"][0] == 1.0
    assert slow["t_coll"][0] == pytest.approx(ref.t_coll, rel=1e-10)
    assert slow["Q"][0] == pytest.approx(ref.Q, rel=1e-6)        # eq. (31) with 0.870925


def test_model_B_restitution_is_johnsons_quarter_power_law():
    # e_B = (8/5)^(3/8) beta^(5/8) (v0/v_y)^(-1/4), eqs. (15), (26)-(28)
    pair = Pair()
    beta = pair.b2 / pair.b1
    for v_hat in (50.0, 1e3, 1e5):
        c = collide(v_hat * pair.v_y, pair, "B")
        assert c.e == pytest.approx(1.6**0.375 * beta**0.625 * v_hat**-0.25, rel=1e-10)


def test_classical_forms_meet_one_at_yield_and_fall_as_quarter_power():
    assert F.thornton_e(1.0) == pytest.approx(1.0, rel=1e-12)
    assert F.johnson_e(1.0) == 1.0
    v = np.array([1e6, 1e8])
    slope = np.diff(np.log(F.thornton_e(v))) / np.diff(np.log(v))
    assert slope[0] == pytest.approx(-0.25, abs=1e-4)


def test_fit_rejects_unknown_model_and_array_b():
    with pytest.raises(ValueError, match="no fitted relations for contact model .D.; fitted: A, B, C"):
        collide_fit(np.array([1.0]), Pair(), "D")
    with pytest.raises(ValueError, match="scalars"):
        collide_fit(np.array([1.0]), Pair(b1=np.array([1.1, 1.2]), b2=3.0), "A")
