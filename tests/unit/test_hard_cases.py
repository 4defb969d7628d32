"""Hard cases stay numerically stable: extreme speeds, ratios, sizes and materials.

Every output finite, delta_max increasing with v0, unphysical results flagged exactly
when e > 1 or delta_f < 0, and the fast path within 1e-6 of the exact one.
"""
import math

import numpy as np
import pytest

from plugins.heat import MODELS, Pair, collide
from plugins.heat.exact import FLAG_TOL
from plugins.heat.fast import collide_fast

PAIRS = {
    "paper": Pair(),
    "wall": Pair.wall(),
    "mass ratio 1e-3": Pair(R1=1e-3, R2=1e-3, rho1=10.0, rho2=10000.0),
    "mass ratio 1e3": Pair(R1=1e-3, R2=1e-3, rho1=10000.0, rho2=10.0),
    "size ratio 1e-3": Pair(R1=2e-6, R2=2e-3),
    "size ratio 1e3": Pair(R1=2e-3, R2=2e-6),
    "10 um particles": Pair(R1=10e-6, R2=10e-6),
    "very soft": Pair(Estar=1e6, Y=1e5, rho1=900, rho2=900),
    "very stiff": Pair(Estar=1e12, Y=5e9, rho1=15000, rho2=15000),
    "b2 close to b1": Pair(b1=1.1, b2=1.2),
}
SPEEDS = np.geomspace(1e-9, 1e3, 25)


def _onset_speeds(pair):
    v_y, v_p = pair.onset_speeds()
    return [v * f for v in (v_y, v_p) for f in (1 - 1e-9, 1 + 1e-9)]


@pytest.mark.parametrize("model", sorted(MODELS))
@pytest.mark.parametrize("name", sorted(PAIRS))
def test_hard_cases_finite_monotone_flagged(name, model):
    pair = PAIRS[name]
    speeds = np.sort(np.concatenate([SPEEDS, _onset_speeds(pair)]))
    results = [collide(v, pair, model) for v in speeds]
    for c in results:
        values = [getattr(c, k) for k in ("t_max", "delta_max", "a_max", "F_max", "delta_r", "delta_f",
                                          "R_bar", "t_r", "v1", "e", "t_coll", "Q", "Q_closed_form")]
        assert all(math.isfinite(x) for x in values), (c.v0, values)
        assert min(c.t_max, c.delta_max, c.a_max, c.F_max, c.t_r, c.v1, c.Q) > 0
        unphysical = c.delta_f < -FLAG_TOL * c.delta_max or c.e > 1 + FLAG_TOL
        assert bool(c.flags) == unphysical, (c.v0, c.flags, c.e, c.delta_f)
    assert np.all(np.diff([c.delta_max for c in results]) > 0)


@pytest.mark.parametrize("model", sorted(MODELS))
@pytest.mark.parametrize("name", ["paper", "wall", "mass ratio 1e-3", "10 um particles", "very soft",
                                  "very stiff", "b2 close to b1"])
def test_fast_path_agrees_with_exact_on_hard_cases(name, model):
    pair = PAIRS[name]
    speeds = np.sort(np.concatenate([SPEEDS, _onset_speeds(pair)]))
    fast = collide_fast(speeds, pair, model)
    for j, v in enumerate(speeds):
        c = collide(v, pair, model)
        for key in ("e", "t_coll", "delta_max", "Q", "F_max", "delta_r", "t_r"):
            assert fast[key][j] == pytest.approx(getattr(c, key), rel=1e-6), (v, key)
        assert fast["flags"][j] == (1 * ("negative_residual_indentation" in c.flags)
                                    | 2 * ("restitution_above_one" in c.flags))
