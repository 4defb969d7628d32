from __future__ import annotations

import numpy as np

from plugins.drag.ergun import ergun
from plugins.drag.wenyu import wen_yu


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


MODEL = gidaspow
