from __future__ import annotations

import numpy as np

from plugins.drag._common import reynolds, schiller_naumann


def wen_yu(alpha, slip, d, rho, nu):
    """Wen & Yu, Chem. Eng. Prog. Symp. Ser. 62 (1966) 100-111, at every fluid fraction:
    the dilute branch of :func:`gidaspow` (Schiller-Naumann C_d times alpha^-2.65)."""
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    vp = np.pi * d**3 / 6.0
    cd = schiller_naumann(reynolds(alpha, slip, d, nu))
    return 0.75 * cd * alpha * rho * slip / d * alpha ** (-2.65) * vp


MODEL = wen_yu
