"""Fitted relations: e, t_coll and Q of models A, B, C as explicit functions (the third
evaluation path, after ``exact`` and ``fast``). Pure and vectorised over arrays of v0.

Dimensionless groups (from the scaling of eq. 1 made dimensionless, ``compression.py``):
in units of v_y, delta_y, a_y, t_y = delta_y/v_y and Pair.Q_scale every output of a model
depends only on
  v_hat = v0 / v_y                      impact speed over the speed at first yield (eq. 6);
  beta  = b2 / b1                       fully plastic over first-yield mean pressure;
  v_hat_p = v_p / v_y                   end of the elastic-plastic range, a closed form of
                                        b1, b2 through X_p = exp(3 (b2 - b1)) (eqs. 9-10).
Material, size, density, E* and Y enter only through v_y, t_y and Q_scale. The position in
the elastic-plastic range is zeta = ln(v_hat) / ln(v_hat_p) (0 at first yield, 1 at full
plasticity).

Structure of each relation (X = a_max^2 / a_y^2, K = 1.4716 of eqs. 23/29):
- v_hat <= 1 (A, C): Hertz, exact: e = 1, t_coll = 2 K v_hat^(-1/5) (eq. 32),
  Q_hat = kappa_H (pi^1/2 / 2) X t_coll^(1/2) with X = v_hat^(4/5), kappa_H = 0.870925 (eq. 31).
- fully plastic skeleton ("hi"), exact for model B and for A, C above v_p: the energy of
  eqs. (7), (11) gives X_hi^2 = X_p^2 + (1.6 v_hat^2 - 4 W_p)/beta (A, C) and
  X = (1.6/beta)^(1/2) v_hat (B, eq. 15); the recovery laws give e = X^(3/4)/v_hat (A,
  eqs. 19-22) and e = beta X^(3/4)/v_hat (B, C, eqs. 26-28, 36-37); every model recovers in
  t_r = K X^(-1/4) (eqs. 23, 29); t_max = pi / (2 (2.5 beta)^(1/2)) (eq. 15);
  Q_hat = kappa(tau) (pi^1/2 / 2) X t_coll^(1/2) (the form of eq. 33) with a fitted
  kappa(tau) = k0 + k1 tau + k2 tau^2 of tau = t_r / t_coll.
- A and C below v_p: y = y_hi exp(g(zeta, beta)) with the fitted correction
  g = (1 - zeta/zc)_+^2 (g0 + g1 zeta + g2 zeta^2 + (g3 + g4 zeta) ln beta).
So model B's e and t_coll are exact closed forms (no constant fitted): e_B = (8/5)^(3/8)
beta^(5/8) v_hat^(-1/4), which is Johnson's (1985) v0^(-1/4) law with his
(Y/E*)^(1/2) (rho v0^2 / Y)^(-1/8) dependence, since v_y ~ Y^(5/2) E*^-2 rho^(-1/2).

e is clipped to at most 1 (the models give e > 1 in their unphysical ranges, see
``exact.flags_for``); the fit of e is stated for the physical range only.

Constants (``CONSTANTS``) come from ``python -m pyhost fit`` (``plugins.heat.refit``):
least squares on ln(y) over a design of 2400 exact collisions, random materials, sizes,
walls, b1 in [1.0, 1.2], b2/b1 in [1.4, 4], v0/v_y log-uniform in [1, 1e5].

Errors (relative, against the exact path at rtol 1e-10; design of 800 pairs per model,
measured max / RMS; e over the physical collisions only) and the bounds stated
(ERROR_BOUND, checked on a fresh random sample by tests/unit/test_fit.py):
  e       A 1.2e-4 / 2.1e-5 (bound 5e-4)   C 1.2e-4 / 1.7e-5 (5e-4)   B exact (1e-12)
  t_coll  A = C 4.2e-2 / 7.9e-3 (bound 6e-2)                          B exact (1e-12)
  Q       A = C 1.5e-2 / 2.1e-3 (bound 2.5e-2)                        B 2.2e-8 (1e-6)
Validity: v0/v_y in (0, 1e5] (below 1 Hertz, exact; above 1e5 the fully plastic skeleton,
exact for e, holds), b1 in [1.0, 1.2], b2/b1 in [1.4, 4], c_log = 3 b1, any materials,
sizes and walls. Model B's kappa(tau) = 0.880 - 0.009 tau: the 0.88 of eq. (33).
"""
from __future__ import annotations

import math

import numpy as np

from plugins.heat.compression import K_HERTZ, _dG
from plugins.heat.models import MODELS

KAPPA_HERTZ = 0.8709254
"""Prefactor of eq. (31) for an exact Hertz impact (the printed 0.87), from the exact path."""

VALIDITY = dict(v_hat=(0.0, 1e5), b1=(1.0, 1.2), beta=(1.4, 4.0))
"""Range of the design the constants were fitted on."""

CONSTANTS = {
    "kappa": (0.880015, -0.00902422, -6.54651e-05),
    ("A", "e"): (1.39609, -0.00041789, 0.00227591, -0.000535828, 0.000372845, -0.00121055),
    ("C", "e"): (1.28285, -0.00071576, 0.00305742, 0.00045798, 0.000779723, -0.00250595),
    ("A", "t_coll"): (1.63647, 0.227805, -0.0741443, 0.265644, -0.0509177, -0.282008),
    ("A", "Q"): (0.721674, 0.104495, -0.272349, 0.704672, -0.0366762, -0.104436),
}
"""Fitted constants: kappa(tau) = (k0, k1, k2); per (model, quantity) (zc, g0, g1, g2, g3, g4).
Model C's t_coll and Q are model A's (same compression and same a_max, eqs. 34-37)."""

ERROR_BOUND = {
    ("A", "e"): 5e-4, ("B", "e"): 1e-12, ("C", "e"): 5e-4,
    ("A", "t_coll"): 0.06, ("B", "t_coll"): 1e-12, ("C", "t_coll"): 0.06,
    ("A", "Q"): 0.025, ("B", "Q"): 1e-6, ("C", "Q"): 0.025,
}
"""Maximum relative error over the physical range of the validity domain."""

FITTED = tuple(sorted({model for model, _ in ERROR_BOUND}))
"""The contact models the relations are fitted for."""


def _laws(model) -> tuple[bool, bool]:
    """(compression fully plastic from the start (Johnson's), recovery by geometric similarity
    (Stronge's)) of a fitted model, from its registry entry (plugins.heat.models)."""
    if model not in FITTED:
        raise ValueError(f"no fitted relations for contact model {model!r}; fitted: {', '.join(FITTED)}")
    m = MODELS.lookup(model)
    return m.compression == "Johnson", m.recovery == "Stronge"

QUANTITIES = ("e", "t_coll", "Q")


def plastic_onset(b1, b2, c=None):
    """(X_p, W_p, v_hat_p): contact area a_p^2/a_y^2 (eq. 9), work to delta_p in units of
    F_y delta_y (eqs. 4, 8), and v_p/v_y, closed forms of b1, b2 and c (default 3 b1)."""
    b1, b2 = np.asarray(b1, float), np.asarray(b2, float)
    c = 3.0 * b1 if c is None else c
    X_p = np.exp(3.0 * (b2 - b1))
    W_p = 0.4 + 0.5 * _dG(X_p, X_p - 1.0, c)
    return X_p, W_p, np.sqrt(W_p / 0.4)


def groups(v_hat, b1, b2, c=None):
    """(beta, v_hat_p, zeta) for impact speeds v_hat = v0/v_y."""
    X_p, W_p, v_hat_p = plastic_onset(b1, b2, c)
    zeta = np.log(np.maximum(v_hat, 1.0)) / np.log(v_hat_p)
    return np.asarray(b2, float) / b1, v_hat_p, zeta


def contact_area(model, v_hat, b1, b2, c=None, iterations=3):
    """X = a_max^2/a_y^2 at the turning point, explicit. Model B: (1.6/beta)^(1/2) v_hat
    (eq. 15). A, C: fully plastic (v_hat >= v_hat_p) X^2 = X_p^2 + (1.6 v_hat^2 - 4 W_p)/beta
    (eqs. 7, 11, exact); elastic-plastic: the energy of eq. (8),
    X^2 (1 + (ln X - 1/2)/c) = 1.6 (v_hat^2 - 1) + 1 - 1/(2c), solved by ``iterations``
    fixed-point steps from X = R^(1/2) (contraction about 1/(2c) per step)."""
    v = np.asarray(v_hat, float)
    b1, b2 = np.asarray(b1, float), np.asarray(b2, float)
    beta = b2 / b1
    if _laws(model)[0]:
        return np.sqrt(1.6 / beta) * v
    c = 3.0 * b1 if c is None else c
    X_p, W_p, v_hat_p = plastic_onset(b1, b2, c)
    X_fp = np.sqrt(np.maximum(X_p**2 + (1.6 * v * v - 4.0 * W_p) / beta, 1e-300))
    R = np.maximum(1.6 * (v * v - 1.0) + 1.0 - 0.5 / c, 1.0 - 0.5 / c)
    X = np.sqrt(R)
    for _ in range(iterations):
        X = np.sqrt(R / (1.0 + (np.log(X) - 0.5) / c))
    return np.where(v >= v_hat_p, X_fp, np.minimum(X, X_p))


def skeleton(model, v_hat, b1, b2, c=None, kappa=None):
    """Explicit skeleton: dict of X, e, t_max, t_r, t_coll, Q (units of a_y^2, t_y,
    Q_scale). e is exact up to the error of ``contact_area``; t_max and Q are
    approximations that the fitted corrections refine (exact for model B up to kappa)."""
    v = np.asarray(v_hat, float)
    b1, b2 = np.asarray(b1, float), np.asarray(b2, float)
    beta = b2 / b1
    c = 3.0 * b1 if c is None else c
    X = contact_area(model, v, b1, b2, c)
    # mean pressure at the turning point in units of b1 Y: eqs. (8), (11)
    plastic, similar = _laws(model)
    p = beta if plastic else np.minimum(1.0 + np.log(np.maximum(X, 1.0)) / c, beta)
    e = (1.0 if similar else p) * X**0.75 / v                         # eqs. (22), (28)
    t_max = 0.5 * math.pi / np.sqrt(2.5 * p)                          # eq. (15) with p
    t_r = K_HERTZ * X**-0.25                                          # eqs. (23), (29)
    t_coll = t_max + t_r
    k0, k1, k2 = CONSTANTS["kappa"] if kappa is None else kappa
    tau = t_r / t_coll
    Q = (k0 + k1 * tau + k2 * tau * tau) * (0.5 * math.sqrt(math.pi)) * X * np.sqrt(t_coll)
    return dict(X=X, e=e, t_max=t_max, t_r=t_r, t_coll=t_coll, Q=Q)


def correction(zeta, beta, p):
    """g(zeta, beta) of the module docstring for constants p = (zc, g0, ..., g4)."""
    zc, g0, g1, g2, g3, g4 = p
    h = np.maximum(1.0 - zeta / zc, 0.0) ** 2
    lb = np.log(beta)
    return h * (g0 + g1 * zeta + g2 * zeta * zeta + (g3 + g4 * zeta) * lb)


def hertz(v_hat):
    """Exact elastic (Hertz) impact: e, t_coll [t_y], Q_hat [Q_scale] (eqs. 4, 31, 32)."""
    v = np.asarray(v_hat, float)
    t = 2.0 * K_HERTZ * v**-0.2
    return dict(e=np.ones_like(v), t_coll=t,
                Q=KAPPA_HERTZ * 0.5 * math.sqrt(math.pi) * v**0.8 * np.sqrt(t))


def dimensionless(model, v_hat, b1, b2, c=None, constants=None):
    """e [-], t_coll [t_y] and Q [Q_scale] by the fitted relations, for v_hat = v0/v_y.
    ``constants`` overrides CONSTANTS (used while fitting)."""
    k = CONSTANTS if constants is None else constants
    v = np.asarray(v_hat, float)
    sk = skeleton(model, v, b1, b2, c, k["kappa"])
    out = {q: sk[q] for q in QUANTITIES}
    if not _laws(model)[0]:                 # Johnson's compression is closed-form (exact)
        beta, _, zeta = groups(v, b1, b2, c)
        for q in QUANTITIES:
            p = k[(model if q == "e" else "A", q)]
            out[q] = sk[q] * np.exp(correction(zeta, beta, p))
        el = v <= 1.0
        if np.any(el):
            h = hertz(np.where(el, v, 1.0))
            for q in QUANTITIES:
                out[q] = np.where(el, h[q], out[q])
    out["e"] = np.minimum(out["e"], 1.0)
    return out


def collide_fit(v0, pair=None, model: str = "A") -> dict:
    """Collisions at normal impact speeds v0 [m/s] (array) by the fitted relations.

    Returns e [-], t_coll [s] and Q [J] (heat from body 1 to body 2, eqs. 2-3) as arrays.
    ``pair`` may hold arrays except b1, b2 (scalars). e never exceeds 1 (clipped where the
    model itself would give e > 1, i.e. outside its physical range). Error bounds (max
    relative error against the exact path, physical range, b1 in [1.0, 1.2], b2/b1 in
    [1.4, 4], v0/v_y <= 1e5): see ERROR_BOUND; c_log other than 3 b1 is not covered.
    """
    from plugins.heat.exact import check_speed
    from plugins.heat.pair import Pair

    pair = Pair() if pair is None else pair
    v0 = check_speed(v0)
    if any(np.ndim(getattr(pair, k)) for k in ("b1", "b2")):
        raise ValueError("collide_fit: b1 and b2 must be scalars")
    d = dimensionless(model, v0 / pair.v_y, float(pair.b1), float(pair.b2),
                      float(pair.log_constant))
    return dict(e=d["e"], t_coll=d["t_coll"] * pair.t_y, Q=d["Q"] * pair.Q_scale)


def johnson_e(v_hat):
    """Johnson's (1985, Contact Mechanics, ch. 11) fully plastic scaling e ~ v0^(-1/4), i.e.
    e ~ (Y/E*)^(1/2) (rho v0^2/Y)^(-1/8), with the prefactor set so that e = 1 at first
    yield: e = min(1, (v0/v_y)^(-1/4)) [-]."""
    return np.minimum(1.0, np.asarray(v_hat, float) ** -0.25)


def thornton_e(v_hat):
    """Thornton (1997, J. Appl. Mech. 64, 383-386) for elastic-perfectly plastic spheres,
    with r = V_y/V_i (V_i > V_y; e = 1 below):
        e = (6 3^(1/2)/5)^(1/2) (1 - r^2/6)^(1/2) [r / (r + 2 (6/5 - r^2/5)^(1/2))]^(1/4).
    The form is quoted from the original paper as we know it (the search tool found no
    public copy to check it against); it gives e = 1 at r = 1 and 1.185 r^(1/4) for r -> 0.
    Thornton's V_y is the speed at first yield of his p_y; we set it to our v_y."""
    v = np.maximum(np.asarray(v_hat, float), 1.0)
    r = 1.0 / v
    e = math.sqrt(6.0 * math.sqrt(3.0) / 5.0) * np.sqrt(1.0 - r * r / 6.0) \
        * (r / (r + 2.0 * np.sqrt(1.2 - 0.2 * r * r))) ** 0.25
    return np.minimum(e, 1.0)
