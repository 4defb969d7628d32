"""The host's collision logic without engines: impact speed (post's back-integration), contact
keys, heat exchange."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from plugins.heat.exchange import exchange_heat
from plugins.dem.hertz import DemHertz
from pyhost.collisions import WALL_BASE, contact_keys

LAW = DemHertz(Ystar=5e7, e=0.8)          # a softened DEM contact
R, M = 1e-3, 2e-5                          # effective radius [m] and mass [kg]


def dem_collision(v0):
    """Forward integration of the DEM law from touch: overlap and its rate over time."""
    rhs = lambda t, y: [y[1], -LAW.force(max(y[0], 0.0), y[1], R, M) / M]
    sep = lambda t, y: y[0] if t > 0 else 1.0
    sep.terminal, sep.direction = True, -1
    return solve_ivp(rhs, (0, 1.0), [0.0, v0], events=sep, dense_output=True, rtol=1e-12, atol=1e-20)


@pytest.mark.parametrize("v0", [0.01, 0.3, 5.0])
@pytest.mark.parametrize("fraction", [0.05, 0.3, 0.45])
def test_impact_speed_recovered_while_approaching(v0, fraction):
    sol = dem_collision(v0)
    d, dd = sol.sol(fraction * sol.t_events[0][0])
    assert dd > 0
    assert LAW.impact_speed(d, dd, R, M)[()] == pytest.approx(v0, rel=5e-5)


@pytest.mark.parametrize("v0", [0.01, 5.0])
def test_impact_speed_recovered_after_turning_point(v0):
    sol = dem_collision(v0)
    d, dd = sol.sol(0.8 * sol.t_events[0][0])
    assert dd < 0
    assert LAW.impact_speed(d, dd, R, M)[()] == pytest.approx(v0, rel=1e-6)


def test_dem_law_rebounds_with_about_its_restitution():
    # LIGGGHTS' beta is exact for a linear spring; with Hertz the rebound is within ~2 %
    sol = dem_collision(1.0)
    assert -sol.y_events[0][0][1] == pytest.approx(LAW.e, rel=2e-2)


def test_bad_dem_parameters():
    with pytest.raises(ValueError, match="restitution"):
        DemHertz(Ystar=1e7, e=1.5)
    with pytest.raises(ValueError, match="modulus"):
        DemHertz(Ystar=-1.0, e=0.5)


def test_contact_keys_order_free_and_walls_distinct():
    assert contact_keys(3, 7) == contact_keys(7, 3)
    assert contact_keys(3, WALL_BASE) != contact_keys(3, 7)
    with pytest.raises(ValueError):
        contact_keys(-1, 2)


def test_heat_exchange_conserves_and_caps():
    rng = np.random.default_rng(3)
    T = rng.uniform(300, 400, 50)
    C = rng.uniform(1e-3, 1e-1, 50)
    i, j = rng.integers(0, 50, 400), rng.integers(0, 50, 400)
    keep = i != j
    i, j = i[keep], j[keep]
    G = rng.uniform(0, 1e-3, i.size)
    G[::7] = 10.0                                    # more than equalisation: capped
    total = np.sum(C * T)
    moved, capped, from_walls = exchange_heat(T, C, i, j, G)
    assert from_walls == 0.0 and capped == len(G[::7])
    assert np.sum(C * T) == pytest.approx(total, rel=1e-12)
    assert T.min() >= 300 - 1e-9 and T.max() <= 400 + 1e-9     # capping never overshoots


def test_heat_flows_with_the_temperatures_of_the_moment():
    # particle 1 first meets the cold 2, then the hot 0: the second exchange sees its new T
    T, C = np.array([400.0, 400.0, 300.0]), np.ones(3)
    moved, capped, _ = exchange_heat(T, C, np.array([1, 1]), np.array([2, 0]), np.array([0.5, 0.5]))
    assert capped == 0 and moved[0] == pytest.approx(50.0) and moved[1] == pytest.approx(-25.0)
    assert T == pytest.approx([375.0, 375.0, 350.0])


def test_heat_exchange_with_walls_balances():
    T = np.array([350.0, 300.0])
    C = np.array([0.01, 0.02])
    T_wall = np.array([320.0, np.nan])          # wall 0 fixed at 320 K, wall 1 adiabatic
    i = np.array([0, 1, 0])
    j = np.array([WALL_BASE, WALL_BASE, WALL_BASE + 1])
    before = np.sum(C * T)
    moved, capped, from_walls = exchange_heat(T, C, i, j, np.array([0.1 / 30, 0.05 / 20, 1.0]), T_wall)
    assert moved[2] == 0.0                       # adiabatic wall
    assert np.sum(C * T) - before == pytest.approx(from_walls, rel=1e-12)
    assert T[0] == pytest.approx(340.0) and T[1] == pytest.approx(302.5)
    # a conductance above the particle's heat capacity is capped: the particle reaches the wall's T
    _, capped, _ = exchange_heat(T, C, np.array([0]), np.array([WALL_BASE]), np.array([10.0]), T_wall)
    assert capped == 1 and T[0] == pytest.approx(320.0)


def exchange_one_by_one(T, C, i, j, G, T_wall):
    """The definition of exchange_heat: one collision after the other (reference)."""
    moved, capped, from_walls = np.zeros(len(G)), 0, 0.0
    for k, (a, b, g) in enumerate(zip(i, j, G)):
        if b >= WALL_BASE:
            tw = T_wall[b - WALL_BASE]
            if np.isnan(tw):
                continue
            limit, dT = C[a], T[a] - tw
        else:
            limit, dT = C[a] * C[b] / (C[a] + C[b]), T[a] - T[b]
        if g > limit:
            g, capped = limit, capped + 1
        q = g * dT
        T[a] -= q / C[a]
        if b >= WALL_BASE:
            from_walls -= q
        else:
            T[b] += q / C[b]
        moved[k] = q
    return moved, capped, from_walls


@pytest.mark.parametrize("seed", range(20))
def test_heat_exchange_in_rounds_is_bit_identical_to_one_by_one(seed):
    # few particles, many collisions: each particle meets several partners in one call,
    # with hot, fixed-temperature and adiabatic walls and capped conductances among them
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(2, 30)), int(rng.integers(1, 300))
    T0, C = rng.uniform(250, 450, n), rng.uniform(1e-4, 1e-1, n)
    i = rng.integers(0, n, m)
    j = np.where(rng.random(m) < 0.2, WALL_BASE + rng.integers(0, 3, m), (i + rng.integers(1, n, m)) % n)
    G = rng.uniform(0, 2e-2, m) * np.where(rng.random(m) < 0.1, 100.0, 1.0)
    T_wall = np.array([320.0, np.nan, 500.0])
    T_ref, T = T0.copy(), T0.copy()
    ref = exchange_one_by_one(T_ref, C, i, j, G, T_wall)
    got = exchange_heat(T, C, i, j, G, T_wall)
    assert np.array_equal(T, T_ref) and np.array_equal(got[0], ref[0])
    assert got[1] == ref[1] and got[2] == ref[2] and str(got[2]) == str(ref[2])


def test_the_bodies_of_collisions_with_particles_and_walls():
    """One lookup for the run, each rank and post: a wall is infinitely large and heavy, made
    of its own material or, where it has none (-1), of the particle's; a particle partner's
    material from its atom type; spheres' masses 4/3 pi R^3 rho where the engine gives none;
    the log numbers walls from 1 (post: by its [[walls]] entry) and particles 0."""
    from types import SimpleNamespace

    from pyhost.collisions import Bodies, log_wall, material_of, wall_code

    glass, steel = SimpleNamespace(density=2500.0), SimpleNamespace(density=7800.0)
    bodies = Bodies([glass, steel], np.array([-1, 0, 1]), np.array([1, -1]))
    j = np.array([7, int(wall_code(0)), int(wall_code(1))])
    mat_i = material_of(bodies.type_material, np.array([1, 2, 2]))
    p = bodies.partners(j, mat_i, np.full(3, 1e-3), material_of(bodies.type_material, np.array([2, 0, 0])),
                        np.full(3, 2e-3))
    assert p.wall.tolist() == [False, True, True] and p.w.tolist() == [0, 0, 1]
    assert p.mat_i.tolist() == [0, 1, 1] and p.mat_j.tolist() == [1, 1, 1]      # wall 1 takes the particle's steel
    assert np.isinf(p.R_j[1:]).all() and np.isinf(p.m_j[1:]).all()
    assert p.m_i[0] == pytest.approx(4 / 3 * np.pi * 1e-9 * 2500.0, rel=1e-15)
    assert p.m_j[0] == pytest.approx(4 / 3 * np.pi * 8e-9 * 7800.0, rel=1e-15)
    assert log_wall(j).tolist() == [0, 1, 2] and log_wall(j, [4, 2]).tolist() == [0, 5, 3]
    assert material_of(bodies.type_material, [5]).tolist() == [-1]
    with pytest.raises(ValueError, match=r"case.toml: atom type\(s\) \[0, 5\] have no material"):
        material_of(bodies.type_material, [1, 0, 5], "case.toml")


def test_the_minimum_image_only_along_periodic_axes():
    """A separation of 0.9 L along a periodic axis is -0.1 L to the nearest image; along a
    fixed axis it stays (box 1 m x 2 m x 4 m, periodic in x and z)."""
    from pyhost.collisions import minimum_image

    d = minimum_image(np.array([[0.9, 1.8, 3.6], [-0.4, -1.9, -2.1]]), np.array([1.0, 2.0, 4.0]),
                      np.array([True, False, True]))
    assert d == pytest.approx(np.array([[-0.1, 1.8, -0.4], [-0.4, -1.9, 1.9]]), abs=1e-15)
