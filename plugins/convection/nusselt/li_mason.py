import numpy as np

from plugins.convection.nusselt import Correlation

EXPONENT = 3.5   # n of the gas fraction: Li & Mason's value for dilute flow (4.75 for dense)


def nusselt(re, pr, alpha):
    """Li, J. & Mason, D.J. (2000), A computational investigation of transient heat transfer
    in pneumatic transport of granular particles, Powder Technology 112, 273-282, eq. (14):

        Nu = 2 + 0.6 a^n Re^(1/2) Pr^(1/3)                                  Re < 200
        Nu = 2 + 0.5 a^n Re^(1/2) Pr^(1/3) + 0.02 a^n Re^0.8 Pr^(1/3)       200 <= Re < 1500
        Nu = 2 + 4.5e-5 a^n Re^1.8                                          Re >= 1500

    with a = ``alpha``, n = 3.5 (as CFDEMcoupling's default) and Re on the superficial slip
    velocity. The first branch is Ranz-Marshall damped by a^n. The branches meet within
    0.4 % at Re = 200 (any Pr) and at Re = 1500 only for Pr near 0.7 (gases), the case the
    authors fitted; they used it up to Re of about 1e5 in dilute pneumatic conveying."""
    re = np.asarray(re, float)
    an = np.power(alpha, EXPONENT)
    p3 = np.cbrt(pr)
    return 2.0 + an * np.where(re < 200.0, 0.6 * np.sqrt(re) * p3,
                               np.where(re < 1500.0, (0.5 * np.sqrt(re) + 0.02 * np.power(re, 0.8)) * p3,
                                        4.5e-5 * np.power(re, 1.8)))


MODEL = Correlation("li_mason", nusselt, dict(re=(0.0, 1e5), pr=(0.6, 1.0), alpha=(0.35, 1.0)),
                          "Li & Mason, Powder Technol. 112 (2000) 273-282, eq. 14")
