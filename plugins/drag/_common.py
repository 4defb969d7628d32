"""What the drag laws share: the particle Reynolds number and the single-sphere drag
coefficient."""
from __future__ import annotations

import numpy as np


def reynolds(alpha, slip, d, nu):
    """Particle Reynolds number on the superficial slip velocity, alpha |u - v| d / nu (-);
    floored at 1e-12 so that the laws stay finite at zero slip."""
    return np.maximum(alpha * slip * d / nu, 1e-12)


def schiller_naumann(re):
    """Single-sphere drag coefficient (-), Schiller & Naumann (1933): 24/Re (1 + 0.15
    Re^0.687) below Re = 1000, 0.44 above."""
    return np.where(re < 1000.0, 24.0 / re * (1.0 + 0.15 * re**0.687), 0.44)
