import numpy as np

from plugins.convection.nusselt import Correlation


def nusselt(re, pr, alpha):
    """Gunn, D.J. (1978), Transfer of heat or mass to particles in fixed and fluidised beds,
    Int. J. Heat Mass Transfer 21, 467-476, eq. (29):

        Nu = (7 - 10 a + 5 a^2)(1 + 0.7 Re^0.2 Pr^(1/3)) + (1.33 - 2.4 a + 1.2 a^2) Re^0.7 Pr^(1/3)

    with a the gas fraction ``alpha`` and Re on the superficial slip velocity. At a = 1 it is
    2 (1 + 0.7 Re^0.2 Pr^(1/3)) + 0.13 Re^0.7 Pr^(1/3), a single sphere (Nu = 2 at Re = 0).
    Gunn fitted fixed and fluidised beds with 0.35 <= a <= 1 and Re up to 1e5."""
    return gunn_form(re, pr, alpha, (7.0, -10.0, 5.0, 0.7, 1.33, -2.4, 1.2))


def gunn_form(re, pr, alpha, c):
    """(c0 + c1 a + c2 a^2)(1 + c3 Re^0.2 Pr^(1/3)) + (c4 + c5 a + c6 a^2) Re^0.7 Pr^(1/3): Gunn's
    form, which later fits (``deen``) keep with other coefficients ``c``."""
    a = np.asarray(alpha, float)
    p3 = np.cbrt(pr)
    return ((c[0] + c[1] * a + c[2] * a**2) * (1.0 + c[3] * np.power(re, 0.2) * p3)
            + (c[4] + c[5] * a + c[6] * a**2) * np.power(re, 0.7) * p3)


MODEL = Correlation("gunn", nusselt, dict(re=(0.0, 1e5), pr=(0.6, 1e3), alpha=(0.35, 1.0)),
                          "Gunn, Int. J. Heat Mass Transfer 21 (1978) 467-476, eq. 29")
