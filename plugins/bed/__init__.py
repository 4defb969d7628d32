"""Correlations of packed and fluidized beds: Ergun's pressure drop and the minimum
fluidization velocity (Wen & Yu; Ergun against the bed's weight). What a fluidization
curve is measured against (``pyhost.fluidization``). SI units: m/s, Pa, m, kg/m^3, Pa s;
pure vectorised functions.
"""
from __future__ import annotations

import numpy as np


def ergun_pressure_drop(u, eps, d, height, rho, mu):
    """Ergun (1952): pressure drop [Pa] across a packed bed of height [m] and voidage eps
    of spheres of diameter d [m], at superficial velocity u [m/s] of a fluid of density rho
    [kg/m^3] and dynamic viscosity mu [Pa s]."""
    return height * (150 * (1 - eps)**2 * mu * u / (eps**3 * d**2) + 1.75 * (1 - eps) * rho * u**2 / (eps**3 * d))


def wen_yu_umf(d, rho_p, rho, mu, g=9.81):
    """Wen & Yu (1966), AIChE J. 12, 610: Re_mf = (33.7^2 + 0.0408 Ar)^1/2 - 33.7 with
    Ar = d^3 rho (rho_p - rho) g / mu^2; returns u_mf = Re_mf mu / (rho d) [m/s]."""
    ar = d**3 * rho * (rho_p - rho) * g / mu**2
    return (np.sqrt(33.7**2 + 0.0408 * ar) - 33.7) * mu / (rho * d)


def ergun_umf(eps, d, rho_p, rho, mu, g=9.81):
    """u_mf [m/s] where Ergun's pressure gradient equals the bed weight per volume less
    buoyancy, (1 - eps)(rho_p - rho) g, at voidage eps."""
    a = 150 * (1 - eps)**2 * mu / (eps**3 * d**2)
    b = 1.75 * (1 - eps) * rho / (eps**3 * d)
    c = (1 - eps) * (rho_p - rho) * g
    return (-a + np.sqrt(a * a + 4 * b * c)) / (2 * b)
