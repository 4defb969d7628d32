import numpy as np

from plugins.conduction.contact import ContactModel
from plugins.conduction.contact.lethe import contact_radius


def microcontact_resistance(pair):
    """R_mc = 1.184 / (pi k_h a^2) (sigma / m) (H_c / p_max)^0.96 [K/W]: the resistance of the
    asperities inside the contact (Lethe, github.com/chaos-polymtl/lethe commit 0e6a3dc,
    source/dem/particle_heat_transfer.cc, calculate_microcontact_resistance; Van Lew, PhD
    thesis, UCLA 2016, eqs. 3.25-3.27), with a the corrected contact radius (``lethe``),
    k_h the harmonic mean conductivity, sigma, m, H_c the pair's equivalent roughness, slope
    and microhardness (``Pair``), and the Hertz peak pressure of the real material
    p_max = 2 E*_real delta_real / (pi a), delta_real = delta (E*_dem / E*_real)^(2/3) (same
    file, calculate_contact_thermal_conductance). 0 for smooth surfaces (sigma = 0)."""
    a = contact_radius(pair)
    ratio = np.asarray(pair.E_dem, float) / np.asarray(pair.E_real, float)
    delta = np.clip(pair.overlap, 0.0, None) * ratio ** (2.0 / 3.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        p_max = 2.0 * np.asarray(pair.E_real, float) * delta / (np.pi * a)
        R = (1.184 / (np.pi * pair.harmonic_conductivity * a * a) * np.asarray(pair.roughness, float)
             / np.asarray(pair.slope, float) * (np.asarray(pair.microhardness, float) / p_max) ** 0.96)
    return np.where(np.asarray(pair.roughness, float) > 0, R, 0.0)


def conductance(pair):
    """H = 1 / (R_Mc + R_mc) [W/K]: Lethe's contact path of rough spheres, its macrocontact
    resistance R_Mc = 0.5 / (a k_h) (``lethe``) in series with the microcontact resistance
    (``microcontact_resistance``). Lethe puts the gas microgap in parallel with the
    microcontact (source/dem/particle_heat_transfer.cc, lines 215-217); it is left out here
    (the contact models take no gas): for Beaulieu's steel beads (sigma 27 nm, m 0.079,
    H_c 3 GPa, p_max ~ 1e8 Pa) its resistance is some 100 times the microcontact's, so leaving
    it out lowers H by about 1 % of R_mc's share. Equal to ``lethe`` for smooth surfaces.

    Valid for static (lasting) contacts, a << R, 0 < 2 p_max / H_c < 2 (the asperities'
    plastic regime of the correlation)."""
    touching = pair.overlap > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        R_macro = 0.5 / (contact_radius(pair) * pair.harmonic_conductivity)
        H = 1.0 / (R_macro + microcontact_resistance(pair))
    return np.where(touching, H, 0.0)


MODEL = ContactModel("lethe_rough", conductance,
                     "Lethe source/dem/particle_heat_transfer.cc, macro- and microcontact (Van Lew 2016, eqs. 3.25-3.27)")
