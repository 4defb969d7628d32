"""Compression laws of Kosinski et al. (2014), made dimensionless.

Units: indentation x = delta/delta_y, squared contact radius A = a^2/a_y^2, force
F/F_y, work W/(F_y delta_y), speed v/v_y, time t/(delta_y/v_y) (scales in ``pair.py``).
In these units the equation of motion m* d2delta/dt2 = -F becomes
v^2 = v0^2 - 2.5 W(x), so that the Hertz work to first yield is W(1) = 0.4 and the
impact speed at first yield is 1. Every output then depends on v0/v_y, b1 and b2 only
(and on the constant of eq. 8): the models are self-similar, which the fast path uses.

The time to travel from x_top - w up to the turning point x_top is tau(w) = int dw/v.
It is evaluated with the substitution w = s^2, under which the integrand 2 s / v(s^2) is
smooth (v ~ s near the turning point), and differences of work are formed so that no
digits cancel near the turning point (``work_drop``).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numpy.polynomial import Chebyshev

from plugins.dem.hertz import K_HERTZ  # noqa: F401  (re-exported: the 1.472 of eqs. 23 and 29)


def hertz_time_from_top(w, x_top, t_half, y=None):
    """Time [t_y] for a Hertz contact to go from indentation y = x_top - w up to its turning
    point x_top, given the half-collision time t_half. Accurate for w -> 0 (no cancellation);
    pass y as well where it is known more precisely than x_top - w."""
    from scipy.special import betainc, betaincc   # here: only the exact path and table builds need them

    w = np.minimum(np.asarray(w, float), x_top)
    y = x_top - w if y is None else np.asarray(y, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        near = w < 0.5 * x_top
        one_minus_z = -np.expm1(2.5 * np.log1p(-np.where(near, w, 0.0) / x_top))
        z = (np.maximum(y, 0.0) / x_top) ** 2.5
    return t_half * np.where(near, betainc(0.5, 0.4, one_minus_z), betaincc(0.4, 0.5, z))


def cheb_antiderivative(f, a: float, b: float, rtol: float) -> Chebyshev:
    """Antiderivative (zero at a) of a smooth f on [a, b], from its Chebyshev interpolant.

    The degree doubles from 16 until the last coefficients fall below rtol/10 of the
    largest (Clenshaw-Curtis with an error estimate), at most 2048.
    """
    n = 16
    while True:
        p = Chebyshev.interpolate(f, n, domain=[a, b])
        c = np.abs(p.coef)
        if c[-3:].max() <= max(0.1 * rtol, 1e-15) * c.max() or n >= 2048:
            return p.integ(lbnd=a)
        n *= 2


class FromTop:
    """Antiderivative I(w) = int_w1^w f dw' on a piece [w1, w2] of the distance w from a
    turning point at ``top``, where f may behave like w^(1/p - 1) as w -> 0.

    Near the turning point (w1 small against the piece) the variable is s = w^(1/p), which
    makes the integrand smooth; far from it, the absolute coordinate y = top - w, which keeps
    the piece resolved when top is much larger than the piece. f(w, y) gets both.
    """

    def __init__(self, f, w1: float, w2: float, top: float, p: int, rtol: float):
        self.w1, self.top, self.p = w1, top, p
        self.near = w1 < 0.25 * (w2 - w1)
        if self.near:
            g = lambda s: p * s ** (p - 1) * f(s**p, top - s**p)
            self.F = cheb_antiderivative(g, w1 ** (1.0 / p), w2 ** (1.0 / p), rtol)
        else:
            self.y_hi = top - w1
            self.F = cheb_antiderivative(lambda y: f(top - y, y), top - w2, self.y_hi, rtol)
        self.total = float(self(w2, top - w2))

    def __call__(self, w, y):
        if self.near:
            return self.F(np.asarray(w, float) ** (1.0 / self.p))
        return self.F(self.y_hi) - self.F(y)


def _dG(X1, dX, c):
    """G(X1) - G(X1 - dX) for G(X) = int X (1 + ln X / c) dX, without cancellation."""
    X0 = X1 - dX
    sq = dX * (2.0 * X1 - dX)                      # X1^2 - X0^2
    return sq * (0.5 - 0.25 / c) + (0.5 / c) * (sq * np.log(X1) - X0**2 * np.log1p(-dX / X1))


class Stronge:
    """Compression of model A (and C): Stronge's elastic, elastic-plastic and fully plastic
    ranges, eqs. (4)-(11).

    elastic, x <= 1:            F = x^(3/2),           A = x                 (eqs. 4, 5)
    elastic-plastic, 1..x_p:    F = X (1 + ln X / c),  A = X = 2x - 1        (eqs. 7, 8)
    fully plastic, x >= x_p:    F = (b2/b1) X,         A = X                 (eqs. 7, 11)
    with X_p = (a_p/a_y)^2 = exp(3 (b2 - b1)) and x_p = (X_p + 1)/2 (eqs. 9, 10).
    c = 3 b1 makes F continuous at x_p (the paper's 3.3 for b1 = 1.1).
    """

    name = "Stronge"

    def __init__(self, b1: float, b2: float, c: float):
        self.b1, self.b2, self.c = b1, b2, c
        self.beta = b2 / b1
        self.X_p = math.exp(3.0 * (b2 - b1))                               # eq. (9)
        self.x_p = 0.5 * (self.X_p + 1.0)                                  # eq. (10)
        self.W_p = 0.4 + 0.5 * float(_dG(self.X_p, self.X_p - 1.0, c))
        self.v_hat_p = math.sqrt(self.W_p / 0.4)
        self.a2_breaks = (1.0, self.X_p)

    def regime(self, x_top: float) -> str:
        if x_top <= 1.0:
            return "elastic"
        return "elastic-plastic" if x_top <= self.x_p else "fully plastic"

    def force(self, x):
        x = np.asarray(x, float)
        X = np.maximum(2.0 * x - 1.0, 1.0)
        return np.where(x <= 1.0, np.abs(x) ** 1.5,
                        np.where(x <= self.x_p, X * (1.0 + np.log(X) / self.c), self.beta * X))

    def a2(self, x):
        x = np.asarray(x, float)
        return np.where(x <= 1.0, x, 2.0 * x - 1.0)

    def x_of_a2(self, A):
        A = np.asarray(A, float)
        return np.where(A <= 1.0, A, 0.5 * (A + 1.0))

    def slope(self, x_top: float) -> float:
        """d x / d A in the regime of x_top."""
        return 1.0 if x_top <= 1.0 else 0.5

    def _piece_drop(self, k, x1, L):
        if k == 0:
            return 0.4 * x1**2.5 * -np.expm1(2.5 * np.log1p(-L / x1))
        X1, dX = 2.0 * x1 - 1.0, 2.0 * L
        if k == 1:
            return 0.5 * _dG(X1, dX, self.c)
        return 0.25 * self.beta * dX * (2.0 * X1 - dX)

    def work_drop(self, x_top: float, w, y=None):
        """W(x_top) - W(y) with y = x_top - w: accurate for small w, and for y far below
        x_top when y is given."""
        w = np.asarray(w, float)
        y = x_top - w if y is None else np.asarray(y, float)
        total = np.zeros(np.broadcast(w, y).shape)
        for k, (lo, hi) in enumerate(((0.0, 1.0), (1.0, self.x_p), (self.x_p, math.inf))):
            if x_top <= lo:
                break
            top = min(hi, x_top)
            L = np.clip(w if top == x_top else top - y, 0.0, top - lo)
            with np.errstate(divide="ignore", invalid="ignore"):
                drop = self._piece_drop(k, top, np.where(L > 0, L, 1.0))
            total = total + np.where(L > 0, drop, 0.0)
        return total

    def peak(self, v: float) -> float:
        """Maximum indentation x_max for impact speed v (units of v_y): W(x_max) = 0.4 v^2."""
        if v <= 1.0:
            return v**0.8
        if v <= self.v_hat_p:
            target = 0.4 * (v - 1.0) * (v + 1.0)
            f = lambda L: float(self.work_drop(1.0 + L, L)) - target
            if f(self.x_p - 1.0) <= 0.0:      # v within rounding of v_p
                return self.x_p
            from scipy.optimize import brentq  # here: scipy.optimize takes 0.3 s to import, the fast path never needs it
            L = brentq(f, 0.0, self.x_p - 1.0, xtol=1e-300, rtol=1e-15, maxiter=200)
            return 1.0 + L
        X = math.sqrt(self.X_p**2 + 4.0 * (0.4 * v * v - self.W_p) / self.beta)
        return 0.5 * (X + 1.0)

    def time_from_top(self, v: float, x_top: float, rtol: float):
        """tau(w, y) [t_y]: time from y = x_top - w up to x_top; and t_max."""
        x_star = v**0.8                    # turning point of a purely Hertzian impact
        t_half = K_HERTZ * x_star / v
        if x_top <= 1.0:
            return (lambda w, y=None: hertz_time_from_top(w, x_top, t_half, y)), t_half

        def t_elastic(x):                  # time from contact to x <= 1, eq. (4)
            from scipy.special import betainc
            return t_half * betainc(0.4, 0.5, (np.asarray(x) / x_star) ** 2.5)

        inv_speed = lambda w, y: 1.0 / np.sqrt(2.5 * self.work_drop(x_top, w, y))
        edges = [0.0] + ([x_top - self.x_p] if x_top > self.x_p else []) + [x_top - 1.0]
        pieces, offset = [], 0.0
        for w1, w2 in zip(edges[:-1], edges[1:]):
            if w2 > w1:
                piece = FromTop(inv_speed, w1, w2, x_top, 2, rtol)
                pieces.append((w1, w2, piece, offset))
                offset += piece.total
        w_y, tau_y = x_top - 1.0, offset
        t_el_1 = float(t_elastic(1.0))

        def tau(w, y=None):
            w = np.asarray(w, float)
            y = x_top - w if y is None else np.asarray(y, float)
            out = np.empty(w.shape)
            for w1, w2, piece, off in pieces:
                m = (w >= w1) & (w <= w2)
                out[m] = off + piece(w[m], y[m])
            below = w > w_y
            out[below] = tau_y + t_el_1 - t_elastic(y[below])
            return out

        return tau, tau_y + t_el_1


class Johnson:
    """Compression of model B: Johnson's fully plastic contact from the first touch,
    eqs. (12)-(15): F = pi a^2 b2 Y with a^2 = 2 R* delta, i.e. F = 2 (b2/b1) x and A = 2x.
    Harmonic: x(t) = x_max sin(omega t) with omega^2 = 2.5 b2/b1 (eq. 14); t_max = pi/(2 omega)
    does not depend on v0 (eq. 15)."""

    name = "Johnson"

    def __init__(self, b1: float, b2: float, c: float):
        self.b1, self.b2, self.c = b1, b2, c
        self.beta = b2 / b1
        self.omega = math.sqrt(2.5 * self.beta)
        self.a2_breaks = ()

    def regime(self, x_top: float) -> str:
        return "fully plastic"

    def force(self, x):
        return 2.0 * self.beta * np.asarray(x, float)

    def a2(self, x):
        return 2.0 * np.asarray(x, float)

    def x_of_a2(self, A):
        return 0.5 * np.asarray(A, float)

    def slope(self, x_top: float) -> float:
        return 0.5

    def work_drop(self, x_top: float, w, y=None):
        w = np.asarray(w, float)
        return self.beta * w * (2.0 * x_top - w)

    def peak(self, v: float) -> float:
        return v * math.sqrt(0.4 / self.beta)                              # eq. (15)

    def time_from_top(self, v: float, x_top: float, rtol: float):
        om = self.omega
        tau = lambda w, y=None: 2.0 / om * np.arcsin(np.sqrt(np.minimum(np.asarray(w, float), x_top)
                                                     / (2.0 * x_top)))
        return tau, 0.5 * math.pi / om


COMPRESSION_LAWS = {"Stronge": Stronge, "Johnson": Johnson}


@lru_cache(maxsize=64)
def compression_law(name: str, b1: float, b2: float, c: float):
    """The compression law ``name`` for (b1, b2, c), cached."""
    return COMPRESSION_LAWS[name](b1, b2, c)
