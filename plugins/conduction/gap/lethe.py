import numpy as np

from plugins.conduction.contact.lethe import contact_radius
from plugins.conduction.gap import GapModel


def solid_macrogap_resistance(r, k, a2):
    """R = (pi r / 4) / (pi (r^2 - a^2) k) [K/W] of one particle of radius r [m] and
    conductivity k [W/(m K)] to its contact, a^2 the squared contact radius [m^2]. Lethe
    (commit 0e6a3dc), source/dem/particle_heat_transfer.cc, calculate_solid_macrogap_resistance,
    lines 51-63."""
    return 0.25 * np.pi * r / (np.pi * (r * r - a2) * k)


def gas_macrogap_resistance(R_h, k_g, a2, M):
    """R = 2 / (pi k_g (S ln(S / (S - A)) - A)) [K/W], A = 2 (R_h^2 - a^2)^(1/2),
    S = 2 R_h - a^2 / R_h + M, with R_h = 2 r_i r_j / (r_i + r_j) the harmonic mean of the
    radii [m], k_g the gas conductivity [W/(m K)], a^2 the squared contact radius [m^2] and M
    the gas parameter [m]. Lethe, same file, calculate_interstitial_gas_macrogap_resistance,
    lines 98-111 (after Van Lew, PhD thesis, UCLA, 2016)."""
    A = 2.0 * np.sqrt(R_h * R_h - a2)
    S = 2.0 * R_h - a2 / R_h + M
    return 2.0 / (np.pi * k_g * (S * np.log(S / (S - A)) - A))


def conductance(pair, gas):
    """H = 1 / (R_solid,i + R_solid,j + R_gas) [W/K]: Lethe's macrogap path of a pair in
    contact, the gas between the two spheres outside the contact in series with each sphere's
    solid (source/dem/particle_heat_transfer.cc lines 215-218, the second term of the total
    conductance), a the corrected contact radius of ``contact.lethe``. Lethe computes it for
    pairs in contact only: zero for pairs apart (the particles' gas gaps while apart are not
    in this model; ``rong_horio`` has them).

    Valid for a stagnant gas much less conducting than the solids, a << R. At a = 0 (just
    touching) it stays finite through M > 0 (rarefaction); with M = 0 the gas resistance of a
    point contact vanishes (the logarithm diverges): give gas_parameter > 0."""
    touching = pair.overlap > 0
    a2 = contact_radius(pair) ** 2
    r_i, r_j = np.asarray(pair.r_i, float), np.asarray(pair.r_j, float)
    R_h = 2.0 * r_i * r_j / (r_i + r_j)
    with np.errstate(divide="ignore", invalid="ignore"):
        R = (solid_macrogap_resistance(r_i, pair.k_i, a2) + solid_macrogap_resistance(r_j, pair.k_j, a2)
             + gas_macrogap_resistance(R_h, gas.conductivity, a2, gas.gas_parameter))
        return np.where(touching, 1.0 / R, 0.0)


def reach(r_max, gas):
    """The largest gap [m] at which it conducts: 0 (pairs in contact only)."""
    return 0.0


MODEL = GapModel("lethe", conductance, reach,
                 "Lethe source/dem/particle_heat_transfer.cc lines 51-63, 98-111, 215-218 (Van Lew 2016)")
