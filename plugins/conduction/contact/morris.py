import numpy as np

from plugins.conduction.contact import ContactModel
from plugins.conduction.contact.mfix import conductance as mfix_conductance


def real_overlap(pair):
    """delta_real = (k_dem / k_real)^(2/3) delta [m]: the overlap the real materials would
    have under the same Hertz force. With k = (4/3) E* R*^(1/2) the Hertz stiffness, the ratio
    is E*_dem / E*_real. MFiX, model/des/des_thermo_cond_mod.f line 564 (FUNCTION CORRECT_OLAP,
    the Hertzian branch: ``(HERT_KN(M,L)/HERT_KN_ACTUAL(M,L))**(2.0D0/3.0D0)*OLAP``), with
    HERT_KN_ACTUAL = (4/3) sqrt(R_eff) E_eff of the real moduli (model/check_data/
    check_solids_dem.f line 165). Negative overlaps (pairs apart) are kept as they are."""
    delta = pair.overlap
    ratio = np.asarray(pair.E_dem, float) / np.asarray(pair.E_real, float)
    return np.where(delta > 0, ratio ** (2.0 / 3.0) * delta, delta)


def conductance(pair):
    """H = 2 k_eff a_real [W/K]: ``mfix`` on the overlap corrected for the DEM's softening,
    as MFiX does when the real moduli are given (DO_AREA_CORRECTION, des_thermo_cond_mod.f
    lines 129-136: the centre distance is set to R_i + R_j - delta_real, then a follows from
    it). Morris, A.B., Pannala, S., Ma, Z., Hrenya, C.M., "Development of soft-sphere contact
    models for thermal heat conduction in granular flows", AIChE J. 62 (2016) 4526-4535.

    For a Hertz contact held by force F, a_real = (3 F R* / 4 E*_real)^(1/3)
    = (E*_dem / E*_real)^(1/3) a_dem: this is the static contact of the real material under the
    DEM's force. Equal moduli give ``mfix``. Valid for static (lasting) contacts, a << R; for a
    collision's contact the collision heat models are the ones (Kosinski et al. 2014)."""
    return mfix_conductance(pair._replace(distance=pair.r_i + pair.r_j - real_overlap(pair)))


MODEL = ContactModel("morris", conductance,
                     "MFiX des_thermo_cond_mod.f lines 129-136, 564 (Morris et al., AIChE J. 62, 2016)")
