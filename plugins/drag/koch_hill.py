from __future__ import annotations

import numpy as np

from plugins.drag._common import reynolds


def koch_hill(alpha, slip, d, rho, nu):
    """Koch & Hill, Annu. Rev. Fluid Mech. 33 (2001) 619-647, from the lattice-Boltzmann fits
    of Hill, Koch & Ladd, J. Fluid Mech. 448 (2001) 213-241 and 243-278, in the form of van
    Buijtenen et al., Chem. Eng. Sci. 66 (2011) 2368-2376 (the Reynolds number on the
    diameter, hence 0.5 F3), as CFDEMcoupling's KochHillDrag in its model A:

        K = V_p 18 nu rho / d^2 alpha^2 (F0 + 0.5 F3 Re),  Re = alpha |u - v| d / nu,
        F0 = [1 + 3 sqrt(phi/2) + 135/64 phi ln(phi) + 16.14 phi]
             / [1 + 0.681 phi - 8.48 phi^2 + 8.16 phi^3]          (phi < 0.4)
        F0 = 10 phi / alpha^3                                      (phi >= 0.4)
        F3 = 0.0673 + 0.212 phi + 0.0232 / alpha^5,               phi = 1 - alpha.

    At alpha = 1 it is Stokes' drag with a small inertial term (3 pi mu d (1 + 0.045 Re));
    in a dense bed at low Re, Carman-Kozeny's 180 where Ergun has 150. Fitted for
    Re up to about 100 and solid fractions up to about 0.6."""
    alpha, slip, d = np.asarray(alpha, float), np.asarray(slip, float), np.asarray(d, float)
    phi = np.clip(1.0 - alpha, 1e-12, 1.0 - 1e-12)
    re = reynolds(alpha, slip, d, nu)
    dilute = ((1.0 + 3.0 * np.sqrt(phi / 2.0) + 135.0 / 64.0 * phi * np.log(phi) + 16.14 * phi)
              / (1.0 + 0.681 * phi - 8.48 * phi**2 + 8.16 * phi**3))
    f0 = np.where(phi < 0.4, dilute, 10.0 * phi / alpha**3)
    f3 = 0.0673 + 0.212 * phi + 0.0232 / alpha**5
    return 18.0 * nu * rho / d**2 * alpha**2 * (f0 + 0.5 * f3 * re) * np.pi * d**3 / 6.0


MODEL = koch_hill
