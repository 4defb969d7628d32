"""Fluid-particle drag laws, registered by name.

Each law is a pure vectorised function

    law(alpha, slip, d, rho, nu) -> K

of the fluid volume fraction ``alpha`` around each particle (-), the magnitude of the slip
velocity ``|u - v|`` between interstitial fluid and particle (m/s), the particle diameter
``d`` (m), the fluid density ``rho`` (kg/m^3) and kinematic viscosity ``nu`` (m^2/s). It
returns the drag coefficient of each particle ``K`` (kg/s): the drag force on the particle
is ``K (u - v)`` (N), and the same force with the opposite sign acts on the fluid of its
cell. For a volume-averaged momentum exchange coefficient beta (kg/m^3/s, Gidaspow's
notation), ``K = beta V_p / (1 - alpha)``.

The pressure-gradient (buoyancy) force ``-V_p grad p`` is not part of a law: the fluid
solver is in "model A" form (Zhou, Kuang, Chu, Yu, J. Fluid Mech. 661 (2010) 482-510,
set II) and the host adds it separately.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

DragLaw = Callable[..., np.ndarray]
LAWS: dict[str, DragLaw] = {}


def register(name: str):
    def add(law: DragLaw) -> DragLaw:
        LAWS[name] = law
        return law
    return add


def get(name: str) -> DragLaw:
    """The law registered as ``name``; ValueError listing the choices otherwise."""
    try:
        return LAWS[name]
    except KeyError:
        raise ValueError(f"unknown drag law '{name}'; choices: {', '.join(sorted(LAWS))}") from None


def _reynolds(alpha, slip, d, nu):
    """Particle Reynolds number on the superficial slip velocity, alpha |u - v| d / nu (-);
    floored at 1e-12 so that the laws stay finite at zero slip."""
    return np.maximum(alpha * slip * d / nu, 1e-12)


def _schiller_naumann(re):
    """Single-sphere drag coefficient (-), Schiller & Naumann (1933): 24/Re (1 + 0.15
    Re^0.687) below Re = 1000, 0.44 above."""
    return np.where(re < 1000.0, 24.0 / re * (1.0 + 0.15 * re**0.687), 0.44)


@register("difelice")
def di_felice(alpha, slip, d, rho, nu):
    """Di Felice, Int. J. Multiphase Flow 20 (1994) 153-159, eqs. 7, 13 and 16.

    F = 1/2 C_d rho (pi d^2 / 4) alpha^2 |u - v| (u - v) alpha^(-chi), with
    C_d = (0.63 + 4.8 / sqrt(Re))^2 (Dallavalle), Re = alpha |u - v| d / nu and
    chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2). Fitted for 0.4 <= alpha <= 1 and
    1e-2 < Re < 1e4; at alpha = 1 it is the single-sphere drag of Dallavalle's C_d.
    """
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    re = _reynolds(alpha, slip, d, nu)
    cd = (0.63 + 4.8 / np.sqrt(re)) ** 2
    chi = 3.7 - 0.65 * np.exp(-0.5 * (1.5 - np.log10(re)) ** 2)
    return 0.125 * cd * rho * np.pi * d**2 * alpha**2 * slip * alpha ** (-chi)


@register("gidaspow")
def gidaspow(alpha, slip, d, rho, nu):
    """Gidaspow, Multiphase Flow and Fluidization (1994), eqs. 5.49-5.50: Ergun's equation
    below alpha = 0.8, Wen & Yu (1966) above.

    alpha < 0.8:  beta = 150 (1 - alpha)^2 rho nu / (alpha d^2) + 1.75 (1 - alpha) rho |u - v| / d
    alpha >= 0.8: beta = 3/4 C_d alpha (1 - alpha) rho |u - v| / d alpha^(-2.65),
                  C_d from Schiller-Naumann at Re = alpha |u - v| d / nu.
    K = beta V_p / (1 - alpha). In a fixed bed (v = 0) the Ergun branch gives exactly
    Ergun's pressure drop with this solver's -alpha grad p. Discontinuous at alpha = 0.8.
    """
    return np.where(np.asarray(alpha) < 0.8, ergun(alpha, slip, d, rho, nu),
                    wen_yu(alpha, slip, d, rho, nu))


@register("ergun")
def ergun(alpha, slip, d, rho, nu):
    """Ergun (1952) at every fluid fraction: the dense branch of :func:`gidaspow`.
    Only meaningful for packed beds (alpha below about 0.8)."""
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    vp = np.pi * d**3 / 6.0
    return (150.0 * (1.0 - alpha) * rho * nu / (alpha * d**2) + 1.75 * rho * slip / d) * vp


@register("wenyu")
def wen_yu(alpha, slip, d, rho, nu):
    """Wen & Yu, Chem. Eng. Prog. Symp. Ser. 62 (1966) 100-111, at every fluid fraction:
    the dilute branch of :func:`gidaspow` (Schiller-Naumann C_d times alpha^-2.65)."""
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    vp = np.pi * d**3 / 6.0
    cd = _schiller_naumann(_reynolds(alpha, slip, d, nu))
    return 0.75 * cd * alpha * rho * slip / d * alpha ** (-2.65) * vp
