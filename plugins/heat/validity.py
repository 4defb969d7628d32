"""Where a collision leaves the range of the models and of their evaluation paths.

``check_scales(pair)``: ValueError naming the pair's values when its reference scales (the
yield speed v_y, indentation delta_y, time t_y, force F_y, heat Q_scale of pair.py) are not
finite (and but for Q_scale, positive) in double precision (e.g. R = 1e100 m, E* = 1e300 Pa): every output
would be 0/0 or overflow.

``flags(pair, v0, out, method)``: per collision, the ways it is outside validity:
- ``overflow``: an output is not finite in double precision (v0 = 1e300 m/s, dT = 1e308 K);
- ``delta_max_exceeds_radius``: the indentation exceeds the smaller radius, where the
  half-space contact theory of every model (eqs. 4-9, small a/R) has no meaning;
- ``outside_fit_range``: the fitted relations (``fit.py``, ``fit.VALIDITY``) used outside
  v0/v_y <= 1e5, b1 in [1.0, 1.2], b2/b1 in [1.4, 4], c_log = 3 b1.
"""
from __future__ import annotations

import math

import numpy as np

from plugins.heat.fit import VALIDITY

SCALES = ("v_y", "delta_y", "t_y", "a_y", "F_y", "Q_scale")


def check_scales(pair) -> None:
    with np.errstate(all="ignore"):
        bad = [k for k in SCALES if not np.all(np.isfinite(getattr(pair, k)))
               or (k != "Q_scale" and not np.all(getattr(pair, k) > 0))]     # Q_scale has the sign of dT
    if bad:
        raise ValueError(f"R1={pair.R1!r}, R2={pair.R2!r}, rho1={pair.rho1!r}, rho2={pair.rho2!r}, "
                         f"Estar={pair.Estar!r}, Y={pair.Y!r}, dT={pair.dT!r}: the reference scales {', '.join(bad)} are not "
                         f"finite and positive in double precision; outside the range of the models")


def flags(pair, v0: float, out: dict, method: str) -> list[str]:
    """Flags of one collision at speed v0 [m/s] with outputs ``out`` (SI, as Collision)."""
    found = []
    if not all(math.isfinite(v) for v in out.values() if isinstance(v, float)):
        found.append("overflow")
    if "delta_max" in out and out["delta_max"] > min(pair.R1, pair.R2):
        found.append("delta_max_exceeds_radius")
    if method == "fit":
        b1, beta = float(pair.b1), float(pair.b2) / float(pair.b1)
        inside = (v0 / float(pair.v_y) <= VALIDITY["v_hat"][1]
                  and VALIDITY["b1"][0] <= b1 <= VALIDITY["b1"][1]
                  and VALIDITY["beta"][0] <= beta <= VALIDITY["beta"][1]
                  and math.isclose(float(pair.log_constant), 3.0 * b1))
        if not inside:
            found.append("outside_fit_range")
    return found
