"""The frozen-bed thermal stage's integrator (pyhost.frozen) and the probes' means
(pyhost.effects.probes) against exact solutions."""
import numpy as np
import pytest
from scipy.linalg import expm

from pyhost.effects.probes import probe_means
from pyhost.frozen import integrate, system
from pyhost.engines.liggghts.script import ScriptError


def chain(n=6, h=0.02, h_wall=0.05, C=0.6):
    """A 1-D chain of n beads [J/K each], neighbours linked by h [W/K], the first touching a
    wall at 350 K by h_wall [W/K], all at 300 K."""
    i = np.arange(n - 1)
    pairs = (i, i + 1, np.full(n - 1, h))
    walls = (np.array([0]), np.array([350.0]), np.array([h_wall]))
    return np.full(n, C), pairs, walls, np.full(n, 300.0)


def exact(C, pairs, walls, T0, t):
    """T(t) = T_w + expm(-C^-1 A t) (T0 - T_w): every bead tends to the one wall's temperature."""
    A, b = system(C, pairs, walls)
    T_inf = np.linalg.solve(A.toarray(), b)
    return T_inf + expm(-A.toarray() / C[:, None] * t) @ (T0 - T_inf)


def test_system_has_the_wall_temperature_as_its_steady_state():
    C, pairs, walls, T0 = chain()
    A, b = system(C, pairs, walls)
    assert np.allclose(np.linalg.solve(A.toarray(), b), 350.0, rtol=0, atol=1e-9)
    assert np.allclose(A.toarray(), A.toarray().T)


@pytest.mark.parametrize("method", ["implicit", "explicit"])
def test_chain_against_the_matrix_exponential_first_order(method):
    """Backward and forward Euler are first order: the error at 200 s falls by 2 (1.8-2.2)
    when the step halves, and is below 0.05 K at a step of 0.5 s (time constants of the chain
    from 4 s to some 1000 s)."""
    C, pairs, walls, T0 = chain()
    ref = exact(C, pairs, walls, T0, 200.0)
    errors = []
    for step in (1.0, 0.5, 0.25):
        T, Q, dt, steps = integrate(C, pairs, walls, T0, 200.0, step, method)
        errors.append(np.abs(T - ref).max())
        # the balance: what the beads gained is what the wall gave, to round-off
        assert abs(np.sum(C * (T - T0)) - Q) <= 1e-12 * abs(Q)
    assert 1.8 < errors[0] / errors[1] < 2.2 and 1.8 < errors[1] / errors[2] < 2.2
    assert errors[1] < 0.05


def test_explicit_refused_above_its_bound_and_implicit_stable_there():
    C, pairs, walls, T0 = chain()
    bound = 0.6 / (0.02 + 0.05)              # the wall bead: C / (h + h_wall)
    with pytest.raises(ScriptError, match="stability bound"):
        integrate(C, pairs, walls, T0, 10 * 1.01 * bound, 1.01 * bound, "explicit")
    T, *_ = integrate(C, pairs, walls, T0, 1000.0, 100.0, "implicit")    # 10 steps, 12x the bound
    assert np.all((T >= 300.0) & (T <= 350.0))


def test_rows_every_and_at_the_end():
    C, pairs, walls, T0 = chain()
    times = []
    integrate(C, pairs, walls, T0, 10.0, 0.3, "implicit", every=3.0, on_row=lambda t, T, Q: times.append(t))
    # 34 steps of 10/34 s: a row every 10 steps (2.94 s) and one at the end
    assert np.allclose(times, [k * 10.0 / 34 for k in (10, 20, 30, 34)])


def test_probe_means_are_capacity_weighted_and_nan_when_empty():
    x = np.array([[0.0, 0, 0.1], [0.0, 0, 0.2], [0.0, 0, 0.5]])
    T = np.array([300.0, 400.0, 1000.0])
    C = np.array([1.0, 3.0, 1.0])
    regions = dict(low=[-1, 1, -1, 1, 0.0, 0.3], empty=[-1, 1, -1, 1, 0.6, 0.7])
    low, empty = probe_means(regions, x, T, C)
    assert low == pytest.approx((300.0 + 3 * 400.0) / 4, rel=1e-15)
    assert np.isnan(empty)
