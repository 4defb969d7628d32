"""Lasting conduction models (plugins.conduction): MFiX's published rates for its two DEM
verification problems, the models' limits and scalings, the corrections of the softened
overlap, and the pair exchange (exact for a pair at any interval, conservative, bounded)."""
import numpy as np
import pytest
from scipy.integrate import quad

from plugins.conduction import CONTACT, GAP, Gas, Pair, exchange
from plugins.conduction.gap.rong_horio import half_lens

CAL = 4.1868                         # J: one calorie, for MFiX's CGS values (k and c alike)
R1, R2 = 0.15e-2, 0.18e-2            # m: radii of particle_input.dat (D_p0 0.30 and 0.36 cm)
K1, K2 = 0.131453 * CAL * 1e2, 0.002008 * CAL * 1e2          # W/(m K)
C1 = 420.0 * 4 / 3 * np.pi * R1**3 * 0.191204 * CAL * 1e3    # J/K: m c
C2 = 8850.0 * 4 / 3 * np.pi * R2**3 * 0.013145 * CAL * 1e3
GAS = Gas(1.239e-4 * CAL * 1e2)      # K_g0 of the particle-fluid-particle problem
TOUCHING = (0.4799731 - 0.1499864) * 1e-2     # m: centre distance of the contact problem
APART = (1.498 - 1.150) * 1e-2                # m: of the particle-fluid-particle problem


def pair(distance, E_dem=1e8, E_real=1e8, r_i=R1, r_j=R2, k_i=K1, k_j=K2):
    return Pair(r_i, r_j, distance, k_i, k_j, E_dem, E_real)


def test_registries_hold_the_models_and_refuse_others_with_the_list():
    assert list(CONTACT) == ["lethe", "lethe_rough", "mfix", "morris"] and list(GAP) == ["lethe", "rong_horio"]
    with pytest.raises(ValueError, match="unknown contact conduction model 'zhou'; choices: lethe, lethe_rough, mfix, morris"):
        CONTACT.lookup("zhou")
    with pytest.raises(ValueError, match="unknown gap conduction model 'bob'; choices: lethe, rong_horio"):
        GAP.lookup("bob")


def test_mfix_gives_the_rates_of_mfix_contact_conduction_problem():
    """MFiX legacy_tests/dem-tests/contact-conduction (usr2_des.f): A_C = H / (m1 c1) =
    0.01027998273952850 1/s and B_C = H / (m2 c2) = 0.00410668176759131 1/s, to 1e-12."""
    H = CONTACT["mfix"].conductance(pair(TOUCHING))
    assert H / C1 == pytest.approx(0.01027998273952850, rel=1e-12)
    assert H / C2 == pytest.approx(0.00410668176759131, rel=1e-12)


def test_rong_horio_gives_the_rates_of_mfix_pfp_problem_to_7e_5():
    """MFiX legacy_tests/dem-tests/particle-fluid-particle-conduction: A_C = 0.0401067383450698,
    B_C = 0.0160219735083726 1/s. MFiX's closed form (as coded now) gives 6.9e-5 more; so does
    the direct quadrature of its older integral (F, lines 326-336) to 2.3e-6: the published
    rates were not computed from either exactly. Tolerance 1e-4."""
    H = GAP["rong_horio"].conductance(pair(APART), GAS)
    assert H / C1 == pytest.approx(0.0401067383450698, rel=1e-4)
    assert H / C2 == pytest.approx(0.0160219735083726, rel=1e-4)
    assert H / C1 / 0.0401067383450698 - 1 == pytest.approx(6.94e-5, abs=0.05e-5)


def test_rong_horio_closed_form_is_the_integral_over_the_lens():
    """Apart, the pair's conductance is close to k_g times the integral of 2 pi r / h(r) over
    the lens' reach, h the gap between the two spheres at radius r (MFiX's FUNCTION F): to
    1e-5 at gaps of 0.01 to 0.3 R_max (the closed form splits the gap at a plane)."""
    for gap in (0.01, 0.05, 0.1, 0.18 / 1.8, 0.15, 0.19):
        d = R1 + R2 + gap * R2
        cosine = ((1.2 * R2) ** 2 - R1**2 + d**2) / (2 * 1.2 * R2 * d)
        rd = 1.2 * R2 * np.sqrt(1 - cosine**2)
        f = lambda r: 2 * np.pi * r / max(d - np.sqrt(R2**2 - r**2) - np.sqrt(R1**2 - r**2), GAS.min_distance)
        want = GAS.conductivity * quad(f, 0, rd, epsabs=0, epsrel=1e-12, limit=200)[0]
        assert GAP["rong_horio"].conductance(pair(d), GAS) == pytest.approx(want, rel=1e-5), gap


def test_rong_horio_reach_monotony_and_linearity_in_the_gas():
    """Zero from a gap of lens R_max on, positive below, falling as the gap widens between
    particles apart (in contact the solid contact takes the lens' middle: it rises a little as
    the overlap shrinks); twice the gas conductivity, twice the conductance; symmetric in the two
    particles; continuous where the spheres begin to touch."""
    gaps = np.linspace(-0.02, 0.25, 400) * R2
    H = GAP["rong_horio"].conductance(pair(R1 + R2 + gaps), GAS)
    assert np.all(H[gaps >= 0.2 * R2] == 0) and np.all(H[gaps < 0.2 * R2 - 1e-12] > 0)
    inside = (gaps > 0) & (gaps < 0.2 * R2)
    assert np.all(np.diff(H[inside]) < 0)
    H2 = GAP["rong_horio"].conductance(pair(R1 + R2 + gaps), GAS._replace(conductivity=2 * GAS.conductivity))
    assert np.allclose(H2, 2 * H, rtol=1e-14, atol=0)
    swapped = GAP["rong_horio"].conductance(pair(R1 + R2 + gaps, r_i=R2, r_j=R1, k_i=K2, k_j=K1), GAS)
    assert np.array_equal(swapped, H)
    eps = 1e-13
    below, above = (GAP["rong_horio"].conductance(pair(R1 + R2 + s), GAS) for s in (-eps, eps))
    assert below == pytest.approx(above, rel=1e-3)


def test_mfix_contact_radius_is_where_the_spheres_cross():
    """a^2 = 2 R* delta (1 + O(delta/R)): at delta = 1e-6 R*, H = 2 k_eff (2 R* delta)^(1/2)
    to 1e-5; zero apart; symmetric."""
    Rs = R1 * R2 / (R1 + R2)
    k = 2 * K1 * K2 / (K1 + K2)
    for ratio in (1e-8, 1e-6, 1e-4):
        delta = ratio * Rs
        H = CONTACT["mfix"].conductance(pair(R1 + R2 - delta))
        assert H == pytest.approx(2 * k * np.sqrt(2 * Rs * delta), rel=10 * ratio + 1e-7)
    assert CONTACT["mfix"].conductance(pair(R1 + R2 + 1e-9)) == 0
    assert CONTACT["mfix"].conductance(pair(TOUCHING, r_i=R2, r_j=R1, k_i=K2, k_j=K1)) == \
        CONTACT["mfix"].conductance(pair(TOUCHING))


def test_corrections_of_the_softened_overlap():
    """At equal moduli morris is mfix; with the DEM 1000x softer, morris' contact radius is
    1000^(1/3) = 10x smaller (the real material's Hertz contact under the same force) and
    Lethe's 1000^(1/5) x smaller than its uncorrected one; Lethe's radius is the Hertz radius
    (R* delta)^(1/2), 2^(-1/2) of MFiX's crossing circle for small overlaps."""
    same = pair(TOUCHING)
    assert CONTACT["morris"].conductance(same) == CONTACT["mfix"].conductance(same)
    delta = 1e-9
    soft = pair(R1 + R2 - delta, E_dem=1e7, E_real=1e10)
    assert CONTACT["morris"].conductance(soft) == pytest.approx(
        CONTACT["mfix"].conductance(pair(R1 + R2 - delta)) / 10, rel=1e-6)
    assert CONTACT["lethe"].conductance(soft) == pytest.approx(
        CONTACT["lethe"].conductance(pair(R1 + R2 - delta)) / 1000 ** 0.2, rel=1e-12)
    assert CONTACT["lethe"].conductance(pair(R1 + R2 - delta)) == pytest.approx(
        CONTACT["mfix"].conductance(pair(R1 + R2 - delta)) / np.sqrt(2), rel=1e-6)
    for name in CONTACT:
        assert CONTACT[name].conductance(pair(R1 + R2 + 1e-9, E_dem=1e7, E_real=1e10)) == 0


def test_lethe_macrogap_in_contact_only_and_its_limits():
    """Lethe's gas macrogap path: zero apart; in contact, below the solid path alone (the
    solids in series, r/(4 k (r^2 - a^2)) each) and rising towards it as the gas conducts
    better; a larger gas parameter (rarefaction) conducts less."""
    gas = GAS._replace(gas_parameter=1e-7)
    assert GAP["lethe"].conductance(pair(APART), gas) == 0
    touching = pair(TOUCHING)
    H = GAP["lethe"].conductance(touching, gas)
    solid = 1 / (R1 / (4 * K1 * R1**2) + R2 / (4 * K2 * R2**2))
    assert 0 < H < solid
    better = GAP["lethe"].conductance(touching, gas._replace(conductivity=1e4 * GAS.conductivity))
    assert H < better < solid and better == pytest.approx(solid, rel=0.05)
    assert GAP["lethe"].conductance(touching, gas._replace(gas_parameter=1e-5)) < H


@pytest.mark.parametrize("G", [1e-9, 1e-4, 1e-2, 1.0, 1e3])
def test_exchange_of_an_isolated_pair_is_the_exact_relaxation(G):
    """Two bodies C1, C2 through H for a time t (G = H t): T1 relaxes exactly as
    T_eq + (T1 - T_eq) exp(-H t (1/C1 + 1/C2)), whatever G (to 1e-12); energy conserved."""
    T = np.array([298.15, 453.15])
    C = np.array([C1, C2])
    q = exchange(T, C, np.array([0]), np.array([1]), np.array([G]))
    T_new = T + np.array([q[0], -q[0]]) / C
    T_eq = (C1 * T[0] + C2 * T[1]) / (C1 + C2)
    want = T_eq + (T[0] - T_eq) * np.exp(-G * (1 / C1 + 1 / C2))
    assert T_new[0] == pytest.approx(want, rel=1e-12)
    assert np.sum(C * T_new) == pytest.approx(np.sum(C * T), rel=1e-15)


def test_exchange_in_a_network_conserves_energy_and_stays_bounded():
    """100 particles, 400 random pairs, conductances over 12 decades: energy to 1e-14, every
    new temperature within its old neighbourhood's range; at small G, q = G (T_j - T_i)."""
    rng = np.random.default_rng(7)
    T = rng.uniform(250.0, 1250.0, 100)
    C = 10 ** rng.uniform(-4, 0, 100)
    i = rng.integers(0, 100, 400)
    j = (i + rng.integers(1, 100, 400)) % 100
    G = 10 ** rng.uniform(-8, 4, 400)
    q = exchange(T, C, i, j, G)
    T_new = T + (np.bincount(i, q, 100) - np.bincount(j, q, 100)) / C
    assert np.sum(C * T_new) == pytest.approx(np.sum(C * T), rel=1e-14)
    for p in range(100):
        mates = np.r_[j[i == p], i[j == p], p]
        assert T[mates].min() - 1e-9 <= T_new[p] <= T[mates].max() + 1e-9
    small = exchange(T, C, i, j, 1e-12 * G)
    assert np.allclose(small, 1e-12 * G * (T[j] - T[i]), rtol=1e-6)


def test_rong_horio_small_sphere_inside_the_lens_conducts_as_mfix_does():
    """A 0.1 mm sphere touching a 1 mm one lies wholly inside the lens: MFiX's RADIUS gives -1
    (1 m in SI), so both faces conduct whole; the same conductance, to 1e-12, as MFiX's literal
    steps with RD_OUT = -1 m."""
    big, small, s = 1e-3, 1e-4, GAS.min_distance
    d = big + small - 1e-9
    H = GAP["rong_horio"].conductance(pair(d, r_i=small, r_j=big), GAS)
    delta = big + small - d
    x, y = delta / big, (delta + s) / big
    o1 = big**2 * (x - x**2 / 2) / d
    s1 = big**2 * (y - y**2 / 2) / (d - s) - o1
    h1 = half_lens(np.sqrt(1.0 + (small - o1) ** 2), s1, o1, small) * small * GAS.conductivity
    h2 = half_lens(np.sqrt(1.0 + (big - (delta - o1)) ** 2), s - s1, delta - o1, big) * big * GAS.conductivity
    assert H == pytest.approx(h1 * h2 / (h1 + h2), rel=1e-12)


def test_lethe_rough_is_lethe_in_series_with_the_microcontact():
    """Smooth surfaces give ``lethe``; rough ones its macrocontact resistance plus Van Lew's
    microcontact resistance, here written out for one steel pair of Beaulieu's bed (Lethe's
    published values: sigma 19 nm and m 0.056 per surface, H_c 3 GPa, E 200 GPa real, 50 MPa
    softened, nu 0.29), and R_mc falls as p_max^-0.96 (the overlap's p_max^2 ~ delta)."""
    E_dem = 50e6 / (2 * (1 - 0.29**2))
    E_real = 200e9 / (2 * (1 - 0.29**2))
    r, delta = 3.2e-3, 1e-5
    smooth = Pair(r, r, 2 * r - delta, 42.0, 42.0, E_dem, E_real)
    rough = smooth._replace(roughness=np.hypot(19e-9, 19e-9), slope=np.hypot(0.056, 0.056), microhardness=3e9)
    assert CONTACT["lethe_rough"].conductance(smooth) == CONTACT["lethe"].conductance(smooth)
    a = np.sqrt(r / 2 * delta) * (E_dem / E_real) ** 0.2
    p = 2 * E_real * delta * (E_dem / E_real) ** (2 / 3) / (np.pi * a)
    R_mc = 1.184 / (np.pi * 42.0 * a * a) * (np.hypot(19e-9, 19e-9) / np.hypot(0.056, 0.056)) * (3e9 / p) ** 0.96
    assert 0 < 2 * p / 3e9 < 2                              # the correlation's range
    H = CONTACT["lethe_rough"].conductance(rough)
    assert H == pytest.approx(1 / (0.5 / (a * 42.0) + R_mc), rel=1e-12)
    assert H < CONTACT["lethe"].conductance(smooth)
    # p_max ~ delta^(1/2), a^2 ~ delta: R_mc ~ delta^-1 * delta^-0.48
    from plugins.conduction.contact.lethe_rough import microcontact_resistance
    ratio = microcontact_resistance(rough._replace(distance=2 * r - 4 * delta)) / microcontact_resistance(rough)
    assert ratio == pytest.approx(4.0 ** (-1 - 0.48), rel=1e-12)
    assert CONTACT["lethe_rough"].conductance(rough._replace(distance=2 * r + 1e-9)) == 0
