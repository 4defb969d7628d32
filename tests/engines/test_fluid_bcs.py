"""collheatFoam on the pressure conditions users' cases bring (CFDEM tutorials keep
zeroGradient pressure at walls and fixed-velocity inlets): no gas through a wall, a slip
wall or an inlet whatever the pressure condition and the direction of gravity; a pressure
condition the solver cannot honour is refused (exit 2) or stops the run naming the patch
(exit 3), never a wrong flow that ends well."""
import shutil
from pathlib import Path

import numpy as np
import pytest
from foamlib import FoamFile

from pyhost.engines.fluid_case import adopt_void_fraction, box_case
from pyhost.engines.openfoam import FluidCaseError, FluidError, FluidSolver

pytestmark = pytest.mark.engines

AIR = dict(rho=1.2, nu=1.5e-5)                      # kg/m^3, m^2/s
CELL = 0.01                                         # m
N = (4, 4, 8)                                       # cells per axis


def column(tmp_path, *, sides: str, gravity, inlet: float | None, p_sides: dict):
    """A 4 x 4 x 8 cell column; with ``inlet`` (m/s) gas enters at z lo and leaves at z hi
    (p fixed 0), else the box is closed. ``p_sides``: 0/p entry of each wall-like patch
    instead of the fixedFluxPressure the box case writes (the CFDEM way: zeroGradient)."""
    faces = {f: sides for f in ("xlo", "xhi", "ylo", "yhi")}
    faces.update(zlo=("inlet", (0.0, 0.0, inlet)) if inlet is not None else sides,
                 zhi="outlet" if inlet is not None else sides)
    case = box_case(tmp_path / "fluid", lo=(0, 0, 0), hi=tuple(n * CELL for n in N), cells=N,
                    boundaries=faces, gravity=gravity, dt=1e-3, **AIR)
    p = FoamFile(case / "0" / "p")
    for patch, entry in p_sides.items():
        p["boundaryField"][patch] = entry
    return case


def run(case, steps: int = 20):
    with FluidSolver(case) as fluid:
        fluid.advance(steps * 1e-3, steps)
        p, u = fluid.fields()
        return fluid.cell_centres, p, u


ZERO_GRADIENT = {"type": "zeroGradient"}
WALLS = ("xlo", "xhi", "ylo", "yhi")


@pytest.mark.parametrize("gravity", [(0, 0, -9.81), (3.0, -4.0, -8.0)])
def test_closed_box_with_zero_gradient_walls_stays_at_rest(tmp_path, gravity):
    """A closed box of air at rest under gravity (vertical, and tilted: constant/g in any
    direction) with zeroGradient pressure on every wall stays at rest, its pressure
    hydrostatic. Before, gravity drove the gas through the walls (tens of m/s)."""
    case = column(tmp_path, sides="wall", gravity=gravity, inlet=None,
                  p_sides={f: ZERO_GRADIENT for f in (*WALLS, "zlo", "zhi")})
    x, p, u = run(case)
    print(f"max |U| {np.abs(u).max():.3g} m/s")
    assert np.abs(u).max() < 1e-6      # m/s: the pressure solver's tolerance; g dt is 0.01 m/s
    g = np.asarray(gravity, float)
    hydro = AIR["rho"] * (x @ g)                                     # Pa, up to a constant
    print(f"pressure off hydrostatic by {np.ptp(p - hydro):.3g} Pa of {np.ptp(hydro):.3g}")
    assert np.ptp(p - hydro) < 1e-6 * np.ptp(hydro)


def test_inlet_with_zero_gradient_pressure_gives_plug_flow(tmp_path):
    """A column with slip sides, a fixed-velocity inlet at z lo (0.05 m/s) and the outlet at
    z hi, pressure zeroGradient at the inlet and the sides (the CFDEM way), gravity along
    -z: a uniform plug at the inlet speed, the pressure hydrostatic. Before, gravity pulled
    gas out through the inlet."""
    case = column(tmp_path, sides="slip", gravity=(0, 0, -9.81), inlet=0.05,
                  p_sides={f: ZERO_GRADIENT for f in (*WALLS, "zlo")})
    x, p, u = run(case)
    assert u[:, 2] == pytest.approx(0.05, rel=1e-5)
    assert np.abs(u[:, :2]).max() < 1e-6
    slope = np.polyfit(x[:, 2], p, 1)[0]                             # Pa/m along the flow
    assert slope == pytest.approx(-AIR["rho"] * 9.81, rel=1e-5)


def test_fixed_pressure_on_a_wall_is_refused_before_the_first_step(tmp_path):
    """p fixedValue where U is fixed (a wall) sets the flux twice: refused at start, as bad
    input (FluidCaseError, exit 2), naming 0/p and the patch."""
    case = column(tmp_path, sides="wall", gravity=(0, 0, -9.81), inlet=None,
                  p_sides={"xlo": {"type": "fixedValue", "value": 0.0}})
    with pytest.raises(FluidCaseError, match=r"0/p, patch 'xlo': p is fixedValue .* write zeroGradient"):
        run(case)


def test_flux_through_a_wall_stops_the_run_naming_the_patch(tmp_path):
    """A pressure gradient imposed on a wall (fixedGradient) drives gas through it: the
    solver's boundary flux check stops the run (FluidError, exit 3) naming the patch."""
    case = column(tmp_path, sides="wall", gravity=(0, 0, -9.81), inlet=None,
                  p_sides={"yhi": {"type": "fixedGradient", "gradient": 50.0}})
    with pytest.raises(FluidError, match=r"gas flows through patch 'yhi' \(U noSlip, p fixedGradient\)"):
        run(case, steps=2)


SILO_FLUID = Path(__file__).resolve().parents[2] / "cases" / "silo-heat" / "fluid"


def test_o_grid_column_keeps_a_plug_flow(tmp_path):
    """The silo's O-grid of its 25 mm tube (system/blockMeshDict.ogrid: non-orthogonal
    cells where the centre block meets the four outer ones) with slip walls, an inlet at
    0.05 m/s and zeroGradient pressure at inlet and wall (the CFDEM way): 50 steps keep a
    uniform plug and a hydrostatic pressure. Before, the run diverged at its first step
    (Debian's fvc::reconstruct gave wrong velocities on such cells)."""
    case = tmp_path / "fluid"
    shutil.copytree(SILO_FLUID, case, ignore=shutil.ignore_patterns("polyMesh", "[1-9]*", "0.[0-9]*"))
    shutil.copy(case / "system" / "blockMeshDict.ogrid", case / "system" / "blockMeshDict")
    u, p = FoamFile(case / "0" / "U"), FoamFile(case / "0" / "p")
    u["boundaryField"]["inlet"] = {"type": "fixedValue", "value": np.array([0.0, 0.0, 0.05])}
    u["boundaryField"]["wall"] = {"type": "slip"}
    for patch in ("inlet", "wall"):
        p["boundaryField"][patch] = ZERO_GRADIENT
    with FluidSolver(case) as fluid:
        fluid.advance(50 * 1e-4, 50)
        pressure, velocity = fluid.fields()
        x = fluid.cell_centres
    print(f"{len(x)} cells; U_z {velocity[:, 2].min():.6g}..{velocity[:, 2].max():.6g} m/s")
    assert velocity[:, 2] == pytest.approx(0.05, rel=1e-4)
    assert np.abs(velocity[:, :2]).max() < 1e-5
    slope = np.polyfit(x[:, 2], pressure, 1)[0]
    assert slope == pytest.approx(-fluid.rho * 9.81, rel=1e-4)


@pytest.mark.parametrize("cfdem_fraction", [True, False])
def test_inlet_velocity_is_superficial_with_cfdem_void_fraction(tmp_path, cfdem_fraction):
    """CFDEM keeps 0/voidfraction with fixedValue 1 at the inlet: the inlet's velocity is then
    the superficial one even where particles fill the first cells (ErgunTestMPI's bed lies on
    its inlet). adopt_void_fraction gives collheatFoam those conditions as 0/alpha. With a
    fraction of 0.5 in every cell, the gas in the cells moves at 0.05 / 0.5 m/s; without, the
    fraction is zeroGradient and half the gas comes in."""
    case = column(tmp_path, sides="slip", gravity=(0, 0, -9.81), inlet=0.05,
                  p_sides={f: ZERO_GRADIENT for f in (*WALLS, "zlo")})
    if cfdem_fraction:
        vf = FoamFile(case / "0" / "voidfraction")
        vf.class_, vf.object_ = "volScalarField", "voidfraction"
        vf.update({"dimensions": FoamFile.DimensionSet(), "internalField": 1.0,
                   "boundaryField": {"zlo": {"type": "fixedValue", "value": 1.0},
                                     "zhi": {"type": "fixedValue", "value": 1.0},
                                     **{f: {"type": "zeroGradient"} for f in WALLS}}})
        assert adopt_void_fraction(case)
    with FluidSolver(case) as fluid:
        fluid._alpha[:] = 0.5
        fluid.advance(20e-3, 20)
        _, u = fluid.fields()
    # (the outlet's fixed fraction of 1 bends the top cells' flow by about 0.1 %)
    assert u[:, 2] == pytest.approx(0.1 if cfdem_fraction else 0.05, rel=3e-3)
    assert np.median(u[:, 2]) == pytest.approx(0.1 if cfdem_fraction else 0.05, rel=1e-5)


@pytest.mark.parametrize("rule", ["centre", "divided"])
def test_divided_void_fraction_shares_a_particle_between_cells(tmp_path, rule):
    """A 6 mm sphere whose centre lies 1.5 mm (r/2) short of the face between two 10 mm
    cells has 15.6 % of its volume beyond the face (a cap of height r/2). 'centre' gives
    the far cell nothing; 'divided' (15 points) gives it 22 %, within half the cap of the
    exact share. The solid volume is conserved either way."""
    case = box_case(tmp_path / "fluid", lo=(0, 0, 0), hi=(0.02, 0.01, 0.01), cells=(2, 1, 1),
                    boundaries={f: "wall" for f in (*WALLS, "zlo", "zhi")}, dt=1e-3, **AIR)
    d, h = 0.006, 0.0015
    volume = np.pi * d**3 / 6
    cap = np.pi * h**2 * (1.5 * d - h) / 3 / volume                # exact share beyond the face
    with FluidSolver(case, void_fraction=rule) as fluid:
        fluid.particle_forces(np.array([[0.01 - h, 0.005, 0.005]]), np.zeros((1, 3)), np.array([d]))
        solid = (1 - fluid.alpha) * fluid.cell_volumes / volume
    print(f"{rule}: share beyond the face {solid[1]:.3f}, exact {cap:.3f}")
    assert solid.sum() == pytest.approx(1.0, rel=1e-12)
    if rule == "divided":
        assert abs(solid[1] - cap) < 0.5 * cap
    else:
        assert solid[1] == 0.0
