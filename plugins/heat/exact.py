"""The exact path: one collision at a time, to a relative accuracy of about ``rtol``.

Closed forms where the paper has them (Hertz ranges through incomplete beta functions,
model B's harmonic compression, the turning points of the elastic and fully plastic
ranges) and adaptive Chebyshev (Clenshaw-Curtis) quadrature with error control for the
rest. Regime changes are breakpoints of every integral, so none can be stepped over.

Heat, eq. (3) read as Sun & Chen's ring integral: each ring of the contact of radius a
conducts from the moment the growing contact reaches it, t_in(a), until the shrinking
contact releases it, t_out(a), with the flux of eq. (2) and t the time since it touched:
    Q = int_0^a_max 2 pi a (2 dT / sigma) ((t_out - t_in)/pi)^(1/2) da
      = (2 sqrt(pi) dT / sigma) int_0^(a_max^2) (t_out - t_in)^(1/2) d(a^2).
With omega = a_max^2 - a^2 = s^4 near the turning point the integrand is smooth (t_out - t_in ~ omega^(1/2)
near the turning point), so the quadrature converges fast. For a Hertz impact this gives the
0.8709 prefactor of eq. (31).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from plugins.heat.compression import K_HERTZ, FromTop, compression_law, hertz_time_from_top
from plugins.heat.models import MODELS
from plugins.heat.pair import Pair
from plugins.heat.recovery import RECOVERY_LAWS

DEFAULT_RTOL = 1e-11
FLAG_TOL = 1e-12
"""Relative margin below which delta_f < 0 and e > 1 count as rounding, not as flags."""

OUTPUT_KEYS = ("t_max", "delta_max", "a_max", "F_max", "delta_r", "delta_f", "R_bar", "t_r",
               "v1", "e", "t_coll", "Q", "Q_closed_form", "regime", "flags")


def flags_for(x_top, s_r, e) -> list[str]:
    """Where a model leaves physics: negative residual indentation, rebound above impact."""
    flags = []
    if x_top - s_r < -FLAG_TOL * x_top:
        flags.append("negative_residual_indentation")
    if e > 1.0 + FLAG_TOL:
        flags.append("restitution_above_one")
    return flags


def solve(model: str, v: float, b1: float, b2: float, c: float,
          rtol: float = DEFAULT_RTOL, history: bool = False) -> dict:
    """One collision in the units of ``compression.py``: v = v0/v_y; returns x_max, A_max
    (a_max^2/a_y^2), F_max, t_max, s_r (delta_r/delta_y), rho (R_bar/R*), v1, t_r, Q
    (in units of Pair.Q_scale), regime, and with ``history`` the arrays t, x, A, F."""
    m = MODELS.lookup(model)
    law = compression_law(m.compression, b1, b2, c)
    x_top = law.peak(v)
    A_max, F_max = float(law.a2(x_top)), float(law.force(x_top))
    tau_c, t_max = law.time_from_top(v, x_top, rtol)
    s_r, rho = (float(r) for r in RECOVERY_LAWS[m.recovery](law, x_top))
    v1 = rho**0.25 * s_r**1.25                                         # eqs. (22), (28)
    t_r = K_HERTZ * s_r / v1                                           # eqs. (23), (29)
    Q = heat_integral(law, x_top, A_max, tau_c, t_r, rtol)
    out = dict(x_max=x_top, A_max=A_max, F_max=F_max, t_max=t_max, s_r=s_r, rho=rho, v1=v1,
               t_r=t_r, Q=Q, regime=law.regime(x_top))
    if history:
        out.update(_history(law, x_top, tau_c, t_max, s_r, rho, t_r))
    return out


def heat_integral(law, x_top, A_max, tau_c, t_r, rtol) -> float:
    """int_0^A_max (t_out - t_in)^(1/2) dA (eq. 3), pieces split at the regime boundaries;
    omega = A_max - A is the distance from the turning point."""
    slope = law.slope(x_top)
    A_top_lo = max([b for b in law.a2_breaks if b < A_max], default=0.0)

    def root_duration(omega, A):
        x = law.x_of_a2(A)
        w = np.where(A >= A_top_lo, omega * slope, x_top - x)
        return np.sqrt(tau_c(w, x) + hertz_time_from_top(omega, A_max, t_r, A))

    edges = [0.0] + [A_max - b for b in sorted(law.a2_breaks, reverse=True) if b < A_max] + [A_max]
    return sum(FromTop(root_duration, w1, w2, A_max, 4, rtol).total
               for w1, w2 in zip(edges[:-1], edges[1:]) if w2 > w1)


def _history(law, x_top, tau_c, t_max, s_r, rho, t_r, n=200):
    theta = np.linspace(0.0, 0.5 * math.pi, n)
    w = x_top * (1.0 - np.sin(theta))                    # compression, from touch to the turning point
    x_c = x_top - w
    t_c = t_max - tau_c(w)
    s = s_r * np.cos(theta[1:])                          # recovery, from the turning point to release
    t_rec = t_max + hertz_time_from_top(s_r - s, s_r, t_r)
    x_f = x_top - s_r
    return dict(t=np.concatenate([t_c, t_rec]), x=np.concatenate([x_c, x_f + s]),
                A=np.concatenate([law.a2(x_c), rho * s]),
                F=np.concatenate([law.force(x_c), math.sqrt(rho) * s**1.5]))


@dataclass(frozen=True)
class Collision:
    """Outcome of one collision (SI units).

    t_max compression duration [s]; delta_max maximum indentation [m]; a_max maximum contact
    radius [m]; F_max maximum compressive force [N]; delta_r recovery indentation [m];
    delta_f = delta_max - delta_r residual indentation [m]; R_bar effective radius in
    recovery [m]; t_r recovery duration [s]; v1 rebound speed [m/s]; e = v1/v0 [-];
    t_coll = t_max + t_r [s]; Q heat conducted from body 1 to body 2 [J] (eqs. 2-3);
    Q_closed_form eq. (31) if compression stayed elastic, else eq. (33), with the model's own
    a_max and t_coll [J]; regime where compression ended; flags where the model is
    unphysical ("negative_residual_indentation", "restitution_above_one").
    """

    model: str
    v0: float
    t_max: float
    delta_max: float
    a_max: float
    F_max: float
    delta_r: float
    delta_f: float
    R_bar: float
    t_r: float
    v1: float
    e: float
    t_coll: float
    Q: float
    Q_closed_form: float
    regime: str
    flags: tuple
    history: dict | None = field(default=None, repr=False)

    def to_dict(self, keys=OUTPUT_KEYS) -> dict:
        d = asdict(self)
        d["flags"] = list(d["flags"])
        return {k: d[k] for k in keys}

    @property
    def physical(self) -> bool:
        return not self.flags


def closed_form_heat(a_max, t_coll, elastic, dT, sigma):
    """Eq. (31) (elastic, 0.87) or eq. (33) (plastic, 0.88) [J], from a_max [m], t_coll [s],
    dT [K] and sigma of eq. (2)."""
    return np.where(elastic, 0.87, 0.88) * np.pi * a_max**2 * dT * np.sqrt(t_coll) / sigma


def check_speed(v0) -> np.ndarray:
    v = np.asarray(v0, dtype=float)
    if np.any(np.isnan(v)) or np.any(v <= 0) or np.any(np.isinf(v)):
        raise ValueError(f"v0 must be a positive finite impact speed [m/s], got {v0!r}")
    return v


def collide(v0: float, pair: Pair | None = None, model: str = "A", rtol: float = DEFAULT_RTOL,
            history: bool = False) -> Collision:
    """One head-on collision at normal impact speed v0 [m/s] by the exact path."""
    pair = Pair() if pair is None else pair
    v0 = float(check_speed(v0))
    c = float(pair.log_constant)
    d = solve(model, v0 / pair.v_y, float(pair.b1), float(pair.b2), c, rtol, history)
    dy, ay, ty = pair.delta_y, pair.a_y, pair.t_y
    a_max = math.sqrt(d["A_max"]) * ay
    t_max, t_r = d["t_max"] * ty, d["t_r"] * ty
    v1 = d["v1"] * pair.v_y
    e = v1 / v0
    hist = None
    if history:
        hist = dict(t=d["t"] * ty, delta=d["x"] * dy, a=np.sqrt(d["A"]) * ay, F=d["F"] * pair.F_y)
    return Collision(
        model=model, v0=v0, t_max=t_max, delta_max=d["x_max"] * dy, a_max=a_max,
        F_max=d["F_max"] * pair.F_y, delta_r=d["s_r"] * dy, delta_f=(d["x_max"] - d["s_r"]) * dy,
        R_bar=d["rho"] * pair.Rstar, t_r=t_r, v1=v1, e=e, t_coll=t_max + t_r,
        Q=d["Q"] * float(pair.Q_scale),
        Q_closed_form=float(closed_form_heat(a_max, t_max + t_r, d["regime"] == "elastic", pair.dT, pair.sigma)),
        regime=d["regime"], flags=tuple(flags_for(d["x_max"], d["s_r"], e)), history=hist)
