"""Recovery laws of Kosinski et al. (2014), dimensionless (units as in ``compression.py``).

Both are elastic (Hertz) unloading from the turning point with a new effective radius
R_bar and a recovery indentation delta_r (sec. 3.2):
    F = (R_bar/R*)^(1/2) s^(3/2),   a^2 = R_bar (delta - delta_f),   s = delta - delta_f,
so that the rebound speed is v1 = rho^(1/4) s_r^(5/4) (eqs. 22, 28, with rho = R_bar/R*,
s_r = delta_r/delta_y) and the recovery lasts t_r = 1.4716 s_r / v1 (eqs. 23, 29).
Each law returns (s_r, rho) from the compression law and its turning point(s) x_top.
"""
from __future__ import annotations

import numpy as np


def stronge(law, x_top: float) -> tuple[float, float]:
    """Model A, eqs. (16)-(20). Read with "geometric similarity", R_bar = R* delta_r/delta_y
    (eq. 16), and a_max^2 = a_y^2 (2 x_max - 1) (eq. 18), eq. (19) gives
    s_r = (2 x_max - 1)^(1/2) = rho. Then R_bar delta_r = a_max^2: a(t) is continuous at the
    start of recovery. A compression that stayed elastic recovers along Hertz: s_r = x_max,
    rho = 1 (eq. 19 agrees at x_max = 1)."""
    a_max = np.sqrt(law.a2(x_top))
    elastic = np.asarray(x_top) <= 1.0
    return np.where(elastic, x_top, a_max), np.where(elastic, 1.0, a_max)


def johnson(law, x_top: float) -> tuple[float, float]:
    """Models B and C, eqs. (24)-(26) and (34)-(37): the recovery starts at the compression's
    maximum force with the same contact radius, F_max = (4/3) E* R_bar^(1/2) delta_r^(3/2)
    and a_max^2 = R_bar delta_r, so delta_r = 3 F_max / (4 E* a_max) and
    R_bar = 4 E* a_max^3 / (3 F_max); in units s_r = F_max / a_max, rho = a_max^3 / F_max."""
    a_max = np.sqrt(law.a2(x_top))
    F_max = law.force(x_top)
    return F_max / a_max, a_max**3 / F_max


RECOVERY_LAWS = {"Stronge": stronge, "Johnson": johnson}
