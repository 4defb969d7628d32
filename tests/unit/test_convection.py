"""Nusselt correlations (limits and published relations) and the gas-particle exchange over a
coupling interval (conservation, no overshoot at any interval, exact limits)."""
import numpy as np
import pytest

from plugins.convection import CORRELATIONS, conductance, exchange, outside

AIR_PR = 0.71
RE = np.logspace(-3, 4.5, 300)


def test_registry_holds_the_four_and_refuses_others_with_the_list():
    assert {"ranz_marshall", "gunn", "li_mason", "deen"} <= set(CORRELATIONS)
    with pytest.raises(ValueError, match="unknown convection correlation .wakao.; choices: deen, gunn, li_mason, "
                                         "ranz_marshall"):
        CORRELATIONS.lookup("wakao")


@pytest.mark.parametrize("name", sorted(CORRELATIONS))
def test_single_sphere_in_still_gas_conducts_like_a_sphere_in_an_infinite_medium(name):
    """Re -> 0, alpha = 1: Nu -> 2, i.e. G = 2 pi k d, the steady conduction from a sphere
    into an unbounded medium (4 pi k r), to 1e-5 at Re = 1e-30 (Gunn's Re^0.2 term is slow)."""
    k, d = 0.026, 1e-3
    assert CORRELATIONS.lookup(name).nusselt(1e-30, AIR_PR, 1.0) == pytest.approx(2.0, rel=1e-5)
    assert conductance(name, 1e-30, AIR_PR, 1.0, k, d) == pytest.approx(2 * np.pi * k * d, rel=1e-5)


@pytest.mark.parametrize("name", sorted(CORRELATIONS))
def test_nusselt_grows_with_reynolds_number(name):
    for alpha in (0.4, 0.7, 1.0):
        nu = CORRELATIONS.lookup(name).nusselt(RE, AIR_PR, alpha)
        assert np.all(np.isfinite(nu)) and np.all(np.diff(nu) > 0)


def test_ranz_marshall_is_two_plus_the_square_root_law():
    """Nu - 2 scales as Re^(1/2) Pr^(1/3): quadrupling Re doubles it, eightfold Pr doubles it."""
    f = CORRELATIONS.lookup("ranz_marshall").nusselt
    assert (f(400.0, 0.7, 1) - 2) / (f(100.0, 0.7, 1) - 2) == pytest.approx(2.0, rel=1e-12)
    assert (f(100.0, 5.6, 1) - 2) / (f(100.0, 0.7, 1) - 2) == pytest.approx(2.0, rel=1e-12)


def test_gunn_limits():
    """Gunn (1978): at alpha = 1 and Re -> 0 the single sphere's 2; in a packed bed at
    Re -> 0 (alpha = 0.4) 7 - 4 + 0.8 = 3.8; and at alpha = 0.4 it stays within 30 % of
    Wakao & Kaguei's packed-bed Nu = 2 + 1.1 Re^0.6 Pr^(1/3) (Heat and mass transfer in
    packed beds, 1982), fitted independently to partly the same data, for 100 <= Re <= 3000
    (below, Gunn keeps the bed's conduction floor 3.8 where Wakao-Kaguei tends to 2)."""
    f = CORRELATIONS.lookup("gunn").nusselt
    assert f(1e-30, AIR_PR, 1.0) == pytest.approx(2.0, rel=1e-5)
    assert f(1e-30, AIR_PR, 0.4) == pytest.approx(3.8, rel=1e-5)
    re = np.logspace(2, np.log10(3000), 20)
    wakao = 2 + 1.1 * re**0.6 * AIR_PR ** (1 / 3)
    assert np.all(np.abs(f(re, AIR_PR, 0.4) / wakao - 1) < 0.30)


def test_li_mason_reduces_to_ranz_marshall_and_its_branches_meet():
    """Li & Mason (2000): at alpha = 1 and Re < 200 it is Ranz-Marshall; its branches meet
    within 0.4 % at Re = 200 (any Pr) and within 0.5 % at Re = 1500 for a gas (Pr = 0.71)."""
    f = CORRELATIONS.lookup("li_mason").nusselt
    re = np.linspace(0.1, 199, 50)
    assert np.allclose(f(re, 2.0, 1.0), CORRELATIONS.lookup("ranz_marshall").nusselt(re, 2.0, 1.0), rtol=1e-14)
    for alpha in (0.5, 1.0):
        for pr in (0.71, 5.0):
            assert f(200 * (1 + 1e-12), pr, alpha) == pytest.approx(f(200 * (1 - 1e-12), pr, alpha), rel=4e-3)
        assert f(1500 * (1 + 1e-12), AIR_PR, alpha) == pytest.approx(f(1500 * (1 - 1e-12), AIR_PR, alpha), rel=5e-3)
    # the gas fraction damps the convective part as alpha^3.5
    assert (f(100.0, AIR_PR, 0.5) - 2) / (f(100.0, AIR_PR, 1.0) - 2) == pytest.approx(0.5**3.5, rel=1e-12)


def test_deen_is_gunns_form_refitted():
    """Deen et al. (2014): Gunn's conduction floor at Re -> 0 (2 for a single sphere, 3.8 in a
    bed of alpha = 0.4: the first factor is Gunn's); at alpha = 1 and Pr = 1 it is
    2 + 0.34 Re^0.2 + 0.18 Re^0.7 (the published coefficients summed by hand), below Gunn's
    2 + 1.4 Re^0.2 + 0.13 Re^0.7 over its fitted range Re <= 100 (they cross near Re = 450)."""
    f, g = CORRELATIONS.lookup("deen").nusselt, CORRELATIONS.lookup("gunn").nusselt
    for alpha in (0.4, 0.7, 1.0):
        assert f(1e-30, AIR_PR, alpha) == pytest.approx(g(1e-30, AIR_PR, alpha), rel=1e-5)
    re = np.logspace(-2, 2, 30)
    assert np.allclose(f(re, 1.0, 1.0), 2 + 0.34 * re**0.2 + 0.18 * re**0.7, rtol=1e-13)
    assert np.all(f(re, 1.0, 1.0) < g(re, 1.0, 1.0))
    assert outside("deen", [50.0, 150.0], AIR_PR, 0.5) == {"re": 0.5}


def test_validity_flags_name_what_is_outside():
    assert outside("ranz_marshall", [10.0, 300.0], AIR_PR, 1.0) == {"re": 0.5}
    assert outside("gunn", 10.0, AIR_PR, [0.2, 0.5, 0.9, 0.99]) == {"alpha": 0.25}
    assert outside("li_mason", 10.0, AIR_PR, 0.9) == {}


# -- exchange over a coupling interval -------------------------------------------------------

def random_cells(rng, n=200, cells=7):
    d = 10 ** rng.uniform(-6, -2, n)                     # 1 um .. 1 cm
    C_p = 2500 * 840 * np.pi * d**3 / 6                   # glass, J/K
    G = 10 ** rng.uniform(0, 6, n) * np.pi * d**2         # h from 1 to 1e6 W/(m^2 K)
    cell = rng.integers(0, cells, n)
    C_g = 10 ** rng.uniform(-9, -3, cells)
    return rng.uniform(250, 1500, n), C_p, G, cell, rng.uniform(250, 1500, cells), C_g


@pytest.mark.parametrize("dt", [1e-6, 1e-2, 1.0, 1e6])
def test_hard_case_no_overshoot_and_energy_to_round_off(dt):
    """Tiny particles, h up to 1e6 W/(m^2 K), intervals up to 1e6 s (G dt / C up to 1e18):
    each particle ends between its start and its gas's end temperature (to 1e-12), each gas
    within its cell's range, and each cell's energy is conserved to 1e-12 relative."""
    rng = np.random.default_rng(7)
    T_p, C_p, G, cell, T_g, C_g = random_cells(rng)
    q, T_end = exchange(T_p, C_p, G, cell, T_g, C_g, dt)
    T_new = T_p + q / C_p
    gas_new = T_g - np.bincount(cell, q, len(T_g)) / C_g
    lo = np.minimum(T_p, T_end[cell]) * (1 - 1e-12)
    hi = np.maximum(T_p, T_end[cell]) * (1 + 1e-12)
    assert np.all((T_new >= lo) & (T_new <= hi))
    for c in range(len(T_g)):
        mine = cell == c
        if not mine.any():
            continue
        temps = np.r_[T_p[mine], T_g[c]]
        # the gas's temperature comes from the heat it receives: it carries that heat's
        # round-off of the particles' heat contents, up to 1e9 times its own here
        slack = 1e-12 * T_end[c] + 1e-14 * np.sum(C_p[mine] * T_p[mine]) / C_g[c]
        assert temps.min() - slack <= gas_new[c] <= temps.max() + slack
        assert abs(gas_new[c] - T_end[c]) <= slack
        before = np.sum(C_p[mine] * T_p[mine]) + C_g[c] * T_g[c]
        after = np.sum(C_p[mine] * T_new[mine]) + C_g[c] * gas_new[c]
        assert abs(after - before) <= 1e-12 * before
    if dt == 1e6:       # a long interval ends at each cell's equilibrium
        assert np.allclose(T_new, T_end[cell], rtol=1e-12)


def test_particle_in_a_bath_relaxes_exactly():
    """C_g >> C_p: T = T_g + (T0 - T_g) exp(-G t / C) to 1e-12, whatever the interval."""
    C_p, G, T0, Tg = 1e-3, 0.5, 300.0, 900.0
    for dt in (1e-4, 1e-2, 1.0, 100.0):
        q, _ = exchange([T0], [C_p], [G], np.array([0]), [Tg], [1e20], dt)
        assert T0 + q[0] / C_p == pytest.approx(Tg + (T0 - Tg) * np.exp(-G * dt / C_p), rel=1e-12)


def test_one_particle_with_its_gas_converges_to_the_two_body_solution():
    """One particle and a finite gas: the difference decays exactly as exp(-G t (1/C_p +
    1/C_g)); the scheme's error over a fixed time falls as the interval (first order)."""
    C_p, C_g, G, T0, Tg, t = 1.0, 2.0, 1.0, 300.0, 600.0, 1.0
    exact = (C_p * T0 + C_g * Tg) / (C_p + C_g) + (T0 - Tg) * C_g / (C_p + C_g) * np.exp(-G * t * (1 / C_p + 1 / C_g))
    errors = []
    for n in (10, 100, 1000):
        T, gas = T0, Tg
        for _ in range(n):
            q, _ = exchange([T], [C_p], [G], np.array([0]), [gas], [C_g], t / n)
            T, gas = T + q[0] / C_p, gas - q[0] / C_g
        errors.append(abs(T - exact))
    assert errors[1] < errors[0] / 8 and errors[2] < errors[1] / 8
    assert errors[2] < 1e-3 * abs(T0 - Tg)
