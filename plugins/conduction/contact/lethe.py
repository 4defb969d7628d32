import numpy as np

from plugins.conduction.contact import ContactModel


def contact_radius(pair):
    """a = (3 F R* / (4 E*_dem))^(1/3) (E*_dem / E*_real)^(1/5) [m]: Lethe's corrected contact
    radius, with F = (4/3) E*_dem R*^(1/2) delta^(3/2) the elastic Hertz force of the DEM's
    overlap delta (the static contact's: LIGGGHTS' hertz law without its damping, which a
    resting contact does not have), so that the first factor is (R* delta)^(1/2). Lethe
    (github.com/chaos-polymtl/lethe, commit 0e6a3dc), source/dem/particle_heat_transfer.cc,
    calculate_corrected_contact_radius, lines 6-23; the exponent 1/5 is the collision-time
    scaling of Morris et al. (AIChE J. 62, 2016), which Lethe applies to every contact. Lethe
    passes harmonic_radius/2 = R* as the effective radius (line 143 of the same file).
    Zero for pairs apart."""
    delta = np.clip(pair.overlap, 0.0, None)
    ratio = np.asarray(pair.E_dem, float) / np.asarray(pair.E_real, float)
    return np.sqrt(pair.effective_radius * delta) * ratio ** 0.2


def conductance(pair):
    """H = 2 k_h a [W/K]: the inverse of Lethe's macrocontact resistance
    R = 0.5 / (a k_h) (source/dem/particle_heat_transfer.cc, calculate_macrocontact_resistance,
    lines 25-30), k_h = 2 k_i k_j / (k_i + k_j) the harmonic mean and a the corrected contact
    radius (``contact_radius``). Lethe puts it in series with its microcontact and gas-microgap
    resistances, which are in parallel with each other (surface roughness; lines 215-217);
    those are not here: this is a smooth contact's path.

    Valid for static (lasting) contacts, a << R, a gas much less conducting than the solid.
    For equal moduli it is ``mfix`` to first order in the overlap (a^2 = R* delta against
    2 R* delta: Lethe's a is the Hertz contact radius of the force, MFiX's the radius where
    the undeformed spheres cross)."""
    return 2.0 * pair.harmonic_conductivity * contact_radius(pair)


MODEL = ContactModel("lethe", conductance,
                     "Lethe source/dem/particle_heat_transfer.cc lines 6-30 (Morris et al. 2016 correction)")
