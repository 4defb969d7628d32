"""The bed figures of history.csv (pyhost.effects.fluid.FluidExchange.bed_state) are taken
against the case's gravity, whatever its direction: with gravity along -y (a hopper's case)
the pressure drop was NaN on every row, with numpy's warnings, and the bed height was the
z extent. A stand-in fluid here: a hydrostatic gas column and a uniform bed, whose figures
are known exactly."""
from types import SimpleNamespace

import numpy as np
import pytest

from pyhost.effects.fluid import FluidExchange, upwards

RHO, G, H, DP = 1.2, 9.81, 0.1, 50.0


def column(axis: int, sign: float):
    """A 4 x 4 x 10 mesh of a 0.1 m cube under gravity along ``sign`` times ``axis``: the gas's
    hydrostatic pressure plus a bed's drop DP falling linearly over the lower half, and the DEM
    around it: (exchange, atoms) for bed_state."""
    c = (np.arange(10) + 0.5) * H / 10
    grid = np.stack(np.meshgrid((np.arange(4) + 0.5) * H / 4, (np.arange(4) + 0.5) * H / 4, c, indexing="ij"), -1)
    centres = np.roll(grid.reshape(-1, 3), axis - 2, axis=1)     # the 10-cell direction along ``axis``
    g = np.zeros(3)
    g[axis] = sign * G
    up = -g / G
    height = centres @ up - min(0.0, H * up[axis])
    fluid = SimpleNamespace(cell_centres=centres, rho=RHO, gravity=lambda: g,
                            fields=lambda: (RHO * G * (H - height) + DP * np.clip(1 - height / (H / 2), 0, 1), None))
    rng = np.random.default_rng(1)
    x = rng.uniform(0.0, H, (200_000, 3))
    x[:, axis] *= 0.5                                           # a bed filling the lower half... along +axis
    if sign > 0:
        x[:, axis] = H - x[:, axis]                             # ...or the upper, under gravity along +axis
    loop = SimpleNamespace(scene=SimpleNamespace(fluid=SimpleNamespace(case="fluid")), t=0.0,
                           dem=SimpleNamespace(box=lambda: (np.zeros(3), np.full(3, H), np.zeros(3, bool))))
    return SimpleNamespace(loop=loop, fluid=fluid, up=upwards(fluid), inlet=None), SimpleNamespace(x=x)


@pytest.mark.parametrize("axis, sign", [(2, -1.0), (1, -1.0), (0, 1.0)])
def test_bed_figures_are_taken_against_gravity(axis, sign):
    """The bed's drop between the lowest and highest cell layers (its share at the lowest
    centre, 0.005 m up: 0.9 DP), the hydrostatic head taken off, to 1e-12 Pa; a bed filling
    half the box along gravity: height H/2 to 1 %; u_inlet NaN for a user's case."""
    exchange, atoms = column(axis, sign)
    inlet, drop, height = FluidExchange.bed_state(exchange, atoms)
    assert np.isnan(inlet)
    assert drop == pytest.approx(0.9 * DP, abs=1e-12)
    assert height == pytest.approx(H / 2, rel=1e-2)


def test_upwards_is_against_gravity_and_z_without_it():
    assert upwards(SimpleNamespace(gravity=lambda: np.array([0.0, -9.81, 0.0]))).tolist() == [0.0, 1.0, 0.0]
    assert upwards(SimpleNamespace(gravity=lambda: np.zeros(3))).tolist() == [0.0, 0.0, 1.0]


def test_a_mesh_one_cell_high_along_gravity_has_no_pressure_drop():
    """Cell centres of one layer whose heights differ in their last digits (no gravity: +z;
    a column one cell high): NaN, not a mean of an empty layer with numpy's warnings."""
    import warnings

    from pyhost.effects.fluid import layer_pressure_drop

    centres = np.column_stack([np.linspace(0, 1, 30), np.zeros(30), 0.05 + np.arange(30) * 1e-18])
    fluid = SimpleNamespace(cell_centres=centres, fields=lambda: (np.arange(30.0), None))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.isnan(layer_pressure_drop(fluid, np.array([0.0, 0.0, 1.0])))
