import numpy as np

from plugins.conduction.contact import ContactModel
from plugins.conduction.pair import circle_radius


def conductance(pair):
    """H = 2 k_eff a [W/K]: MFiX's DEM contact conduction, Batchelor & O'Brien (1977) as
    modified by Musser (2011), with the contact radius a of the overlap as the DEM has it.

    MFiX (classic, 2016 tree; mirror github.com/truongd8593/mfix), model/des/des_thermo_cond_mod.f:
    line 144 ``Q_pp = 2.0d0 * lK_eff * lRadius * DeltaTp``, with

        k_eff = 2 k_i k_j / (k_i + k_j)                      (FUNCTION K_eff, line 302)
        a = R_max sin(beta), cos(beta) = (R_max^2 - R_min^2 + d^2) / (2 R_max d)
                                                             (FUNCTION RADIUS, lines 259-287)

    where d is the centre distance and R_max, R_min the larger and smaller radius: a is the
    radius of the circle where the two spheres' surfaces cross (a^2 = 2 R* delta to first
    order in the overlap delta). Zero for pairs apart (line 126).

    Batchelor, G.K., O'Brien, R.W., Proc. R. Soc. Lond. A 355 (1977) 313-333: for a contact
    radius a much smaller than the radii and conductivities much above the gas', each sphere
    is a half-space fed through a circle of radius a, resistance 1/(4 k a); the two in series
    give H = 4 a k_i k_j / (k_i + k_j) = 2 k_eff a. Musser, J., PhD thesis, West Virginia
    University (2011).

    Valid for a static contact, a << R, and a gas much less conducting than the solid (the
    gas path is a gap model's). It takes the overlap as the DEM gives it: with a softened DEM
    modulus that overlap, and so a, is too large (``morris``, ``lethe`` correct it)."""
    R_max, R_min = np.maximum(pair.r_i, pair.r_j), np.minimum(pair.r_i, pair.r_j)
    touching = pair.overlap > 0
    a = np.where(touching, circle_radius(R_max, R_min, pair.distance), 0.0)
    return 2.0 * pair.harmonic_conductivity * np.maximum(a, 0.0)


MODEL = ContactModel("mfix", conductance,
                     "MFiX des_thermo_cond_mod.f lines 126-144 (Batchelor & O'Brien 1977, modified by Musser 2011)")
