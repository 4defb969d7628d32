from __future__ import annotations

import numpy as np

from plugins.drag._common import reynolds


def di_felice(alpha, slip, d, rho, nu):
    """Di Felice, Int. J. Multiphase Flow 20 (1994) 153-159, eqs. 7, 13 and 16.

    F = 1/2 C_d rho (pi d^2 / 4) alpha^2 |u - v| (u - v) alpha^(-chi), with
    C_d = (0.63 + 4.8 / sqrt(Re))^2 (Dallavalle), Re = alpha |u - v| d / nu and
    chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2). Fitted for 0.4 <= alpha <= 1 and
    1e-2 < Re < 1e4; at alpha = 1 it is the single-sphere drag of Dallavalle's C_d.
    """
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    re = reynolds(alpha, slip, d, nu)
    cd = (0.63 + 4.8 / np.sqrt(re)) ** 2
    chi = 3.7 - 0.65 * np.exp(-0.5 * (1.5 - np.log10(re)) ** 2)
    return 0.125 * cd * rho * np.pi * d**2 * alpha**2 * slip * alpha ** (-chi)


MODEL = di_felice
