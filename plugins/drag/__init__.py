"""Fluid-particle drag laws, registered by name: one module per law, file name = key
(the value of ``[fluid] drag``).

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

import numpy as np

from plugins.registry import Registry

LAWS = Registry(__name__, __path__, "drag law")
"""{name: law}; ``LAWS.lookup(name)`` for a message naming the choices."""


def fluid_fraction(solid, volumes, alpha_min: float):
    """Each cell's fluid volume fraction (-): 1 less its particles' volume ``solid`` [m^3] over
    the cell's volume [m^3], floored at ``alpha_min`` (the "centre" rule: a particle's whole
    volume in the cell of its centre)."""
    return np.maximum(1.0 - solid / volumes, alpha_min)


def fluid_force(k, slip, vp, rho: float, gradp):
    """The fluid's force on each particle [N] (n, 3) in model A (module doc): drag ``K (u - v)``
    (``k`` [kg/s], ``slip`` u - v [m/s], (n, 3)) plus the pressure gradient's
    ``-V_p rho grad(p/rho)`` (``vp`` [m^3], ``rho`` [kg/m^3], ``gradp`` the kinematic pressure
    gradient [m/s^2], (n, 3))."""
    return k[:, None] * slip - (vp * rho)[:, None] * gradp
