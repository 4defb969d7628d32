from __future__ import annotations

import numpy as np


def ergun(alpha, slip, d, rho, nu):
    """Ergun (1952) at every fluid fraction: the dense branch of :func:`gidaspow`.
    Only meaningful for packed beds (alpha below about 0.8)."""
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    vp = np.pi * d**3 / 6.0
    return (150.0 * (1.0 - alpha) * rho * nu / (alpha * d**2) + 1.75 * rho * slip / d) * vp


MODEL = ergun
