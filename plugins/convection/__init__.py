"""Gas-particle convection: Nusselt correlations by name (``nusselt/``, one file each) and
the exchange of heat between particles and the gas of their cells over a coupling interval
(``exchange``). Pure functions, SI units.

- ``CORRELATIONS``: the Nusselt correlations by name (``plugins.registry.Registry``);
- ``conductance(name, re, pr, alpha, k_g, d)``: G = h A = Nu k_g / d * pi d^2 [W/K];
- ``outside(name, re, pr, alpha)``: per quantity, the fraction of values outside the range
  where the correlation rests on data (an extrapolation there, not an error);
- ``exchange(...)``: see ``plugins.convection.exchange``;
- ``particle_reynolds``, ``prandtl``: the dimensionless groups the correlations take.
"""
from __future__ import annotations

import numpy as np

from plugins.convection.exchange import exchange
from plugins.convection.nusselt import CORRELATIONS, Correlation

__all__ = ["CORRELATIONS", "Correlation", "heat_transfer_coefficient", "conductance", "outside", "exchange",
           "particle_reynolds", "prandtl"]


def heat_transfer_coefficient(nu, k_g, d):
    """h = Nu k_g / d [W/(m^2 K)] from the Nusselt number, the gas conductivity k_g
    [W/(m K)] and the particle diameter d [m]."""
    return np.asarray(nu) * k_g / d


def conductance(name: str, re, pr, alpha, k_g, d):
    """Gas-particle conductance G = h pi d^2 [W/K] of each particle by correlation ``name``."""
    return heat_transfer_coefficient(CORRELATIONS.lookup(name).nusselt(re, pr, alpha), k_g, d) * np.pi * np.asarray(d) ** 2


def outside(name: str, re, pr, alpha) -> dict:
    """{quantity: fraction of values outside the correlation's validity range} for each of
    "re", "pr", "alpha" that has any."""
    found = {}
    for key, values in (("re", re), ("pr", pr), ("alpha", alpha)):
        lo, hi = CORRELATIONS.lookup(name).validity[key]
        v = np.atleast_1d(values)
        frac = float(np.mean((v < lo) | (v > hi))) if v.size else 0.0
        if frac > 0:
            found[key] = frac
    return found


def particle_reynolds(alpha, slip, d, nu):
    """Re_p = alpha |u - v| d / nu (-): the superficial slip velocity, as the correlations take it."""
    return np.asarray(alpha) * slip * d / nu


def prandtl(nu, rho, cp, k):
    """Pr = nu rho c_p / k (-) of the gas."""
    return nu * rho * cp / k
