"""``hertz``: Sun & Chen's conduction for an elastic Hertz impact of the real material.

The contact stays elastic at every speed (no yield), with the real effective modulus E* of
the pair. Heat by the ring integral of eq. (3) over the Hertz history, which gives eq. (31):
    Q = 0.87093 pi a_max^2 dT t_coll^(1/2) / sigma,
    a_max^2 = R* delta_max, delta_max = (15 m* v0^2 / (16 E* R*^(1/2)))^(2/5),
    t_coll = 2.8683 (m*^2 / (R* E*^2 v0))^(1/5)                        (eq. 32).
Kosinski et al. (2014), eqs. (31)-(32), after Sun & Chen (1988).

In the units of ``plugins.heat.compression`` a Hertz impact is self-similar:
x_max = v^(4/5), t_coll/t_y proportional to v^(-1/5), and so Q/Q_scale to v^(7/10)
(v = v0/v_y). The model takes the constants from the exact path's own elastic collision at
one speed below yield (``plugins.heat.exact.solve``, closed forms there), so it shares the
exact path's reading of eq. (3) and needs no table. Valid for any v0 > 0 as a model of a
purely elastic contact; beyond v_y the real material yields and models A, B, C apply.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from plugins.heat import exact
from plugins.heat.comparison import ComparisonModel

V_REF = 0.5
"""v0/v_y of the reference collision: elastic for every b1, b2."""


@lru_cache(maxsize=1)
def _reference() -> tuple[float, float]:
    """Q/Q_scale and t_coll/t_y of an elastic impact at v0/v_y = V_REF (b1, b2, c play no part)."""
    d = exact.solve("A", V_REF, 1.1, 2.8, 3.3)
    assert d["regime"] == "elastic"
    return d["Q"], d["t_max"] + d["t_r"]


def heat(v0, pair, dem=None) -> dict:
    v = exact.check_speed(v0) / pair.v_y
    Q_ref, t_ref = _reference()
    Q = Q_ref * (v / V_REF) ** 0.7 * pair.Q_scale
    t_coll = t_ref * (v / V_REF) ** -0.2 * pair.t_y
    delta_max = (15.0 * pair.mstar * np.asarray(v0, float) ** 2 / (16.0 * pair.Estar * np.sqrt(pair.Rstar))) ** 0.4
    return dict(Q=Q, t_coll=t_coll, e=np.full(np.shape(Q), np.nan), delta_max=delta_max)


MODEL = ComparisonModel(
    name="hertz",
    description="Sun & Chen's heat of an elastic Hertz impact with the real modulus (eqs. 31-32)",
    needs_dem=False,
    heat=heat,
)
