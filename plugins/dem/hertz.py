"""The DEM's normal contact law, as LIGGGHTS 3.8 computes it (pair style ``gran model hertz``).

Source: CFDEMproject/LIGGGHTS-PUBLIC, src/normal_model_hertz.h,
``NormalModel<HERTZ>::surfacesIntersect``: kn = (4/3) Y* (R* delta)^(1/2),
gamma_n = -2 (5/6)^(1/2) beta (2 Y* (R* delta)^(1/2) m*)^(1/2), F = kn delta - gamma_n v_n,
and beta from the restitution (``MODEL_PARAMS::createBetaEff``). SI units; pure functions.

Also the contact quantities every layer shares: the effective modulus of two bodies (the
heat plugin's eq. 4 and the DEM's Y*) and the duration of an elastic Hertz impact (eq. 32).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

K_HERTZ = 1.4716375921623523
"""int_0^1 (1 - y^(5/2))^(-1/2) dy = 0.4 B(0.4, 0.5) = 1.4716...: the Hertz half-collision time
in units of delta_max / v0 (the 1.472 of eqs. 23 and 29). Written out, so that a run need not
import scipy.special (0.2 s); tests/unit/test_fast.py checks it against scipy's beta, digit
for digit."""


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* = [(1 - nu1^2)/E1 + (1 - nu2^2)/E2]^-1 [Pa] (Kosinski et al. 2014, sec. 3.1.1,
    after eq. 4; LIGGGHTS' Yeff). Young's moduli E [Pa], Poisson ratios nu [-]."""
    if all(type(a) is float for a in (E1, nu1, E2, nu2)) and 0 < E1 < math.inf and 0 < E2 < math.inf \
            and -1 < nu1 < 0.5 and -1 < nu2 < 0.5:         # plain valid numbers: no numpy round trip
        return 1.0 / ((1 - nu1 * nu1) / E1 + (1 - nu2 * nu2) / E2)
    for name, value in (("E1", E1), ("E2", E2)):
        if not (np.all(np.asarray(value) > 0) and np.all(np.isfinite(value))):
            raise ValueError(f"{name} must be a positive finite Young's modulus [Pa], got {value!r}")
    for name, value in (("nu1", nu1), ("nu2", nu2)):
        if not np.all((np.asarray(value) > -1) & (np.asarray(value) < 0.5)):
            raise ValueError(f"{name} must be a Poisson ratio in (-1, 0.5), got {value!r}")
    return 1.0 / ((1 - np.square(nu1)) / E1 + (1 - np.square(nu2)) / E2)


def reduced(R_i, R_j, m_i, m_j):
    """(R* [m], m* [kg]) of each contact of bodies of radii R and masses m: R_i R_j / (R_i + R_j)
    and m_i m_j / (m_i + m_j); against a wall (R_j, m_j inf) the particle's own R_i, m_i."""
    wall = np.isinf(R_j)
    return (np.where(wall, R_i, R_i * R_j / np.where(wall, 1.0, R_i + R_j)),
            np.where(wall, m_i, m_i * m_j / np.where(wall, 1.0, m_i + m_j)))


def impact_speeds(v0, law_of, key_i, key_j, delta, approach, Rstar, mstar, window, mask=None):
    """Normal impact speeds [m/s] of contacts first seen at overlap delta [m] with approach speed
    [m/s]: for the contacts of each pair of keys (atom types, or materials), that pair's DEM law
    ``law_of(a, b)`` (a ``DemHertz``) integrated back to touch (``DemHertz.impact_speed``) over
    ``window`` [s] (per contact, 0 for none); ``v0`` elsewhere, and outside ``mask``. The one
    recovery of impact speeds from sampled contacts, for the run and for post."""
    v0 = np.array(v0, float)
    window = np.broadcast_to(np.asarray(window, float), np.shape(delta))
    take = np.ones(len(v0), bool) if mask is None else mask
    for a, b in set(zip(np.asarray(key_i)[take].tolist(), np.asarray(key_j)[take].tolist())):
        s = take & (key_i == a) & (key_j == b)
        for w in np.unique(window[s]):
            rows = s & (window == w)
            v0[rows] = law_of(a, b).impact_speed(delta[rows], approach[rows], Rstar[rows], mstar[rows],
                                                 window=w or None)
    return v0


def hertz_collision_time(Estar, Rstar, mstar, v):
    """Duration [s] of an elastic Hertz impact at speed v [m/s] with effective modulus Estar
    [Pa], radius Rstar [m] and mass mstar [kg] (eq. 32)."""
    return 2.0 * K_HERTZ * (15.0 / 16.0) ** 0.4 * (mstar**2 / (Estar**2 * Rstar * v)) ** 0.2


def restitution_beta(e: float) -> float:
    """LIGGGHTS' damping ratio beta = ln e / (ln^2 e + pi^2)^(1/2) (< 0 for e < 1)."""
    if not 0.0 < e <= 1.0:
        raise ValueError(f"DEM restitution must be in (0, 1], got {e!r}")
    if e == 1.0:
        return 0.0
    return math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi**2)


def restitution_of_tsuji_alpha(alpha: float) -> float:
    """The LIGGGHTS restitution e whose Hertz damping is OpenFOAM's spring-slider-dashpot
    damping of coefficient ``alpha`` [-] (Tsuji et al. 1992; OpenFOAM's
    PairSpringSliderDashpot and WallSpringSliderDashpot: eta_n = alpha (m* k_n)^(1/2) delta^(1/4),
    k_n = (4/3) E* R*^(1/2)). With LIGGGHTS' gamma_n above, the two are one law when
    |beta| = alpha / 5^(1/2); then e = exp(pi beta / (1 - beta^2)^(1/2)), inverting
    ``restitution_beta``. Both laws give the same restitution at every speed."""
    if not 0.0 <= alpha < math.sqrt(5.0):
        raise ValueError(f"the dashpot coefficient alpha must be in [0, 5^(1/2)) (|beta| < 1), got {alpha!r}")
    beta = -alpha / math.sqrt(5.0)
    return math.exp(math.pi * beta / math.sqrt(1.0 - beta * beta))


@dataclass(frozen=True)
class DemHertz:
    """The DEM's normal contact law, LIGGGHTS ``model hertz`` (normal_model_hertz.h):
    F = (4/3) Y* (R* delta)^(1/2) delta + 2 (5/6)^(1/2) |beta| (2 Y* (R* delta)^(1/2) m*)^(1/2) ddelta,
    with Y* the DEM's effective (softened) modulus [Pa] and beta from its restitution e."""

    Ystar: float
    e: float

    def __post_init__(self):
        if not self.Ystar > 0:
            raise ValueError(f"DEM effective modulus must be positive, got {self.Ystar!r}")
        object.__setattr__(self, "_damping", 2.0 * math.sqrt(5.0 / 6.0) * abs(restitution_beta(self.e)))

    def force(self, delta, ddelta, Rstar, mstar):
        """Normal force [N] at overlap delta [m] and overlap rate ddelta [m/s]."""
        root = np.sqrt(Rstar * delta)
        return 4.0 / 3.0 * self.Ystar * root * delta + self._damping * np.sqrt(2.0 * self.Ystar * root * mstar) * ddelta

    def max_overlap(self, v, Rstar, mstar):
        """Largest overlap [m] of an undamped collision at normal speed v [m/s]: the kinetic
        energy m* v^2 / 2 equals the Hertz energy (8/15) Y* R*^(1/2) delta^(5/2)."""
        return (15.0 * mstar * np.asarray(v, float) ** 2 / (16.0 * self.Ystar * np.sqrt(Rstar))) ** 0.4

    def impact_speed(self, delta, ddelta, Rstar, mstar, steps: int = 8, window: float | None = None):
        """Normal impact speed [m/s] of contacts first seen at overlap delta [m] with overlap
        rate ddelta [m/s] (> 0 while approaching): the DEM's law integrated back to delta = 0.

        Approaching contacts (ddelta > 0), vectorised: the square speed E = v^2 obeys
        dE/ddelta = -2 F/m*, which stays regular at the turning point (where dv/ddelta does
        not); with delta = delta1 u^4 it is also smooth at touch, and classical RK4 integrates
        it from u = 1 to 0 (relative error below 4e-5 at 8 steps, 3e-6 at 16). Contacts seen later (past half
        their undamped impact energy, or past their turning point) are integrated back in time,
        through the turning point, to delta = 0: vectorised RK4 over ``window`` [s], the time
        since the previous sample within which every new contact began (200 substeps, the
        crossing interpolated), else one by one with solve_ivp.
        """
        delta, ddelta, Rstar, mstar = np.broadcast_arrays(*(np.asarray(a, float) for a in (delta, ddelta, Rstar, mstar)))
        shape = delta.shape
        delta, ddelta, Rstar, mstar = (a.ravel() for a in (delta, ddelta, Rstar, mstar))
        out = np.empty(delta.shape)
        elastic_energy = 16.0 / 15.0 * self.Ystar * np.sqrt(Rstar) * delta**2.5 / mstar
        go = (ddelta > 0) & (ddelta**2 > elastic_energy)      # well before the turning point
        if go.any():
            out[go] = self._back_in_overlap(delta[go], ddelta[go], Rstar[go], mstar[go], steps)
        late = np.flatnonzero(~go)
        if len(late) and window is not None:
            v0, found = self._back_over_window(delta[late], ddelta[late], Rstar[late], mstar[late], window)
            out[late[found]] = v0[found]
            late = late[~found]
        for k in late:
            out[k] = self._back_in_time(delta[k], ddelta[k], Rstar[k], mstar[k])
        return out.reshape(shape)

    def _back_over_window(self, d, v, R, m, window, substeps=200):
        """RK4 backwards in time over ``window``; the speed where the overlap crosses zero."""
        h = -window / substeps
        acc = lambda d, v: -self.force(np.maximum(d, 0.0), v, R, m) / m
        v0, found = np.zeros_like(d), np.zeros(d.shape, bool)
        for _ in range(substeps):
            k1d, k1v = v, acc(d, v)
            k2d, k2v = v + h / 2 * k1v, acc(d + h / 2 * k1d, v + h / 2 * k1v)
            k3d, k3v = v + h / 2 * k2v, acc(d + h / 2 * k2d, v + h / 2 * k2v)
            k4d, k4v = v + h * k3v, acc(d + h * k3d, v + h * k3v)
            d_new = d + h / 6 * (k1d + 2 * k2d + 2 * k3d + k4d)
            v_new = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
            cross = ~found & (d > 0) & (d_new <= 0)
            s = d[cross] / (d[cross] - d_new[cross])
            v0[cross] = v[cross] + s * (v_new[cross] - v[cross])
            found |= cross
            d, v = d_new, v_new
            if found.all():
                break
        return v0, found

    def _back_in_overlap(self, d1, v1, R, m, steps):
        def dE_du(u, E):
            return -8.0 * d1 * u**3 * self.force(d1 * u**4, np.sqrt(np.maximum(E, 0.0)), R, m) / m
        E, h = v1 * v1, -1.0 / steps
        for n in range(steps):
            u = 1.0 + n * h
            k1 = dE_du(u, E)
            k2 = dE_du(u + h / 2, E + h / 2 * k1)
            k3 = dE_du(u + h / 2, E + h / 2 * k2)
            k4 = dE_du(u + h, E + h * k3)
            E = E + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        return np.sqrt(E)

    def _back_in_time(self, d1, v1, R, m):
        from scipy.integrate import solve_ivp  # here: 0.15 s to import, and most runs never come here
        rhs = lambda t, y: [y[1], -self.force(max(y[0], 0.0), y[1], R, m) / m]
        touch = lambda t, y: y[0]
        touch.terminal, touch.direction = True, 0
        t_scale = 10.0 * (m**2 / (self.Ystar**2 * R * max(abs(v1), 1e-6))) ** 0.2 + 10 * d1 / max(abs(v1), 1e-12)
        sol = solve_ivp(rhs, (0.0, -t_scale), [d1, v1], events=touch, rtol=1e-10, atol=1e-30 + 1e-12 * d1)
        if not sol.t_events[0].size:
            raise ValueError(f"contact at overlap {d1:.3g} m, rate {v1:.3g} m/s never separates backwards")
        return float(sol.y_events[0][0][1])
