"""``softened``: the heat LIGGGHTS' ``fix heat/gran`` conducts through one collision of the
DEM's softened spheres, integrated over the DEM's own overlap history.

Conduction (CFDEMproject/LIGGGHTS-PUBLIC, src/fix_heat_gran_conduction.cpp,
``FixHeatGranCond::post_force_eval``, ``contact_area overlap``, the default):
    h = 4 k1 k2 / (k1 + k2) A^(1/2),  flux = h (T_j - T_i),
with A the area of the circle where the two overlapping spheres' surfaces cut,
    A = -pi/4 (r-R1-R2)(r+R1-R2)(r-R1+R2)(r+R1+R2) / r^2,  r = R1 + R2 - delta,
i.e. pi delta (2S - delta)(2R1 - delta)(2R2 - delta) / (4 (S - delta)^2), S = R1 + R2
(about 2 pi R* delta: twice the Hertz area pi R* delta). Against a wall
(src/fix_wall_gran.cpp, ``FixWallGran::addHeatFlux``): A = pi (R1^2 - (R1 - delta)^2).
With ``area_correction yes`` (``FixHeatGranCond::init``) the overlap is first scaled by
    deltan_ratio = (Y*_DEM / Y*_original)^(1 / stressStrainExponent),
with stressStrainExponent = 3/2 for ``model hertz`` (src/normal_model_hertz.h): the
overlap of the real material at the same force. Y*_original uses the DEM's Poisson ratios
with ``youngsModulusOriginal`` (here the real Young's moduli).

Overlap history: LIGGGHTS' ``model hertz`` with its damping (``plugins.dem.hertz.DemHertz``)
from delta = 0 at speed v0 until delta returns to 0 (the normal force may turn slightly
attractive near release; LIGGGHTS' default ``limitForce off`` keeps it so). With
delta_s = (15 m* v0^2 / (16 Y* R*^(1/2)))^(2/5) and t_s = delta_s / v0, delta/delta_s
against t/t_s depends on the restitution only. So one trajectory per restitution is
integrated (DOP853, rtol 1e-12) and every collision's
    Q = dT int h(delta(t)) dt
is a Gauss-Legendre sum over fixed nodes of that trajectory (N_NODES nodes in theta, with
t = t_c (1 - cos theta)/2, which removes the square-root ends). 32 nodes agree with 128 to 2e-10 for
restitutions 0.3-1, and the model agrees with a direct time integration to 1e-6, that
integration's own tolerance (tests/unit/test_comparison.py).

The temperatures are taken as constant over the collision (dT of the pair), as for models
A, B, C; heat/gran itself conducts with the temperatures of each step. t_coll is the DEM
contact time; e is NaN (no feedback). Valid while delta stays below min(R1, R2).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from plugins.dem.hertz import DemHertz
from plugins.heat import exact
from plugins.heat.comparison import ComparisonModel

N_NODES = 32
CHUNK = 8192


@lru_cache(maxsize=64)
def unit_trajectory(restitution: float) -> tuple[np.ndarray, np.ndarray, float]:
    """For R* = m* = Y* = v0 = 1: quadrature nodes x_k = delta/delta_s, weights w_k in units
    of t_s (sum_k w_k f(x_k) = int f dt / t_s over the contact), and t_c / t_s."""
    from scipy.integrate import solve_ivp  # here: 0.15 s to import, only the softened models need it
    law = DemHertz(1.0, restitution)
    d_s = (15.0 / 16.0) ** 0.4
    release = lambda t, y: y[0]
    release.terminal, release.direction = True, -1
    sol = solve_ivp(lambda t, y: [y[1], -law.force(max(y[0], 0.0), y[1], 1.0, 1.0)], (0.0, 20.0),
                    [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-15, dense_output=True, events=release)
    t_c = float(sol.t_events[0][0])
    g, w = np.polynomial.legendre.leggauss(N_NODES)
    theta = 0.5 * math.pi * (g + 1.0)
    t = 0.5 * t_c * (1.0 - np.cos(theta))
    weights = w * 0.5 * math.pi * 0.5 * t_c * np.sin(theta)
    return np.maximum(sol.sol(t)[0], 0.0) / d_s, weights / d_s, t_c / d_s


def contact_area(delta, R1, R2):
    """heat/gran's contact area [m^2] at overlap delta [m] (R2 = inf: a wall)."""
    S = R1 + R2
    with np.errstate(invalid="ignore", divide="ignore"):
        pair = np.pi * delta * (2 * S - delta) * (2 * R1 - delta) * (2 * R2 - delta) / (4 * (S - delta) ** 2)
    return np.where(np.isinf(R2), np.pi * delta * (2 * R1 - delta), pair)


def heat_gran(v0, pair, dem, area_correction: bool) -> dict:
    """Q [J], t_coll [s] and e (NaN) of heat/gran over the DEM collision at v0 [m/s]."""
    v0 = exact.check_speed(v0)
    shape = np.broadcast_shapes(v0.shape, *(np.shape(getattr(pair, f)) for f in ("R1", "R2", "k1", "k2", "dT")))
    flat = lambda a: np.broadcast_to(np.asarray(a, float), shape).ravel()
    v0, R1, R2, Rs, ms = (flat(a) for a in (v0, pair.R1, pair.R2, pair.Rstar, pair.mstar))
    k1, k2, dT = flat(pair.k1), flat(pair.k2), flat(pair.dT)
    x, w, tc = unit_trajectory(float(dem.restitution))
    d_s = (15.0 * ms * v0**2 / (16.0 * dem.Ystar * np.sqrt(Rs))) ** 0.4
    t_s = d_s / v0
    scale = (dem.Ystar / dem.Ystar_original) ** (2.0 / 3.0) if area_correction else 1.0
    Q = np.empty(v0.shape)
    for lo in range(0, len(v0), CHUNK):
        s = slice(lo, lo + CHUNK)
        delta = scale * d_s[s, None] * x
        # beyond the spheres' overlap (delta > 2R, an impact far outside the model's range, flagged
        # by delta_max) the circle they cut has no area: none, not the NaN that spoilt the run's balance
        root_area = np.sqrt(np.maximum(contact_area(delta, R1[s, None], R2[s, None]), 0.0))
        Q[s] = root_area @ w
    Q *= 4.0 * k1 * k2 / (k1 + k2) * t_s * dT
    return dict(Q=Q.reshape(shape), t_coll=(tc * t_s).reshape(shape), e=np.full(shape, np.nan),
                delta_max=(scale * d_s * x.max()).reshape(shape))


MODEL = ComparisonModel(
    name="softened",
    description="LIGGGHTS fix heat/gran over the DEM's softened Hertz overlap (contact_area overlap)",
    needs_dem=True,
    heat=lambda v0, pair, dem: heat_gran(v0, pair, dem, area_correction=False),
)
