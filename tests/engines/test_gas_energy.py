"""Gas energy and gas-particle convection on the real engines (collheatFoam -energy with
LIGGGHTS' Temp): one particle in a hot stream against the lumped solution, and the energy of
particles and gas together against what crossed the fluid's boundaries."""
import csv
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

SCENE = """
[effects]
fluid = true
contact_heat = "{model}"
convection = "{correlation}"

[materials.glass]
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.23
yield_stress = 500e6
heat_capacity = {c}
conductivity = 1.0
dem = {{ youngs_modulus = 5e6, restitution = 0.9 }}

[[particles]]
material = "glass"
count = {count}
radius = 0.5e-3
temperature = 300.0
{where}
velocity_spread = {spread}

{walls}

[domain]
box = [0.0, 0.04, 0.0, 0.04, 0.0, 0.04]

[fluid]
density = 1.2
viscosity = 1.8e-5
conductivity = 0.026
heat_capacity = 1005.0
temperature = 400.0
inlet_velocity = {u}
plenum = {plenum}
cells = [{nx}, 1, 8]

[time]
dem_step = 1e-5
end = {end}
couple_every = {couple}

[output]
every = {every}
vtk = false
pictures = false
"""


def run(tmp_path, **values) -> tuple[dict, list[dict]]:
    case = tmp_path / "case.toml"
    case.write_text(SCENE.format(**values))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    with open(tmp_path / "out" / "history.csv") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    return json.loads((tmp_path / "out" / "summary.json").read_text()), rows


def test_particle_in_a_hot_stream_follows_the_lumped_solution(tmp_path):
    """A 1 mm glass sphere at 300 K resting on the floor in air rising at 1 m/s and 400 K:
    T(t) = Tg + (T0 - Tg) exp(-t / tau), tau = m c / (h pi d^2), h from Ranz-Marshall,
    Nu = 2 + 0.6 Re^(1/2) Pr^(1/3) at Re = u d / nu (written out here, not taken from the
    plugin). Its heat capacity is set to 10 J/(kg K) so that tau is 25 ms. The loop gives a
    particle the heat of a coupling interval at the interval's start, so the history at t is
    compared with T(t + interval). Within 0.5 % of T0 - Tg at every frame over 2 tau (the
    cell's gas, cooled by the particle, stays within 0.03 K of 400 K)."""
    d, rho, c, u, nu, k, cp = 1e-3, 2500.0, 10.0, 1.0, 1.8e-5 / 1.2, 0.026, 1005.0
    summary, rows = run(tmp_path, model="none", correlation="ranz_marshall", c=c, count=1,
                        where="positions = [[0.02, 0.02, 0.0005]]", spread=0.0,
                        walls='[[walls]]\nplane = "zlo"\nmaterial = "glass"', u=u, plenum=0.01, nx=1, couple=10,
                        end=0.06, every=1e-3)
    Re, Pr = u * d / nu, nu * 1.2 * cp / k
    h = (2 + 0.6 * Re**0.5 * Pr ** (1 / 3)) * k / d
    tau = rho * np.pi * d**3 / 6 * c / (h * np.pi * d**2)
    t = np.array([r["time"] for r in rows])
    T = np.array([r["T_mean"] for r in rows])
    expected = 400.0 - 100.0 * np.exp(-(t + 10 * 1e-5) / tau)
    error = np.abs(T - expected) / 100.0
    print(f"tau {tau:.4g} s, max error {error.max():.3%} of T0 - Tg, T_end {T[-1]:.3f} K")
    assert t[-1] >= 2 * tau * 0.99
    assert error.max() < 5e-3
    assert min(r["T_gas_mean"] for r in rows) > 400.0 - 0.03 * 8    # the whole column's mean, 8 layers
    assert abs(summary["total_energy_balance_error"]) < 1e-9


def test_energy_of_particles_and_gas_is_kept_step_by_step(tmp_path):
    """30 glass spheres at 300 K, colliding (model A) and fluidized in a closed-sided box by
    air entering at 400 K into gas at 400 K, adiabatic walls, open top: at each coupling step
    sum(m c T) + sum(rho c alpha V T) - (heat in through the fluid's boundaries) stays
    what it was, to 1e-9 of itself."""
    walls = "\n".join(f'[[walls]]\nplane = "{p}"\nmaterial = "glass"' for p in ("zlo", "xlo", "xhi", "ylo", "yhi", "zhi"))
    summary, rows = run(tmp_path, model="A", correlation="gunn", c=840.0, count=30,
                        where="region = [0.005, 0.035, 0.005, 0.035, 0.001, 0.02]", spread=0.3, walls=walls,
                        u=1.0, plenum=0.0, nx=4, couple=10, end=0.01, every=1e-4)
    total = np.array([r["sum_mcT"] + r["gas_energy"] - r["heat_through_fluid_boundaries"] - r["heat_from_walls"]
                      for r in rows])
    step = np.abs(np.diff(total)) / total[1:]
    print(f"{len(rows)} steps, largest change {step.max():.2e} of the total, heat convected "
          f"{rows[-1]['heat_convected']:.4g} J, collisions {summary['collisions']}")
    assert rows[-1]["heat_convected"] > 1e-3           # the exchange did work: about 4 mJ
    assert step.max() < 1e-9
    assert abs(summary["total_energy_balance_error"]) < 1e-9
    assert abs(summary["energy_balance_error"]) < 1e-12


def schumann_gas(xi, eta):
    """Schumann (1929), J. Franklin Inst. 208, 405-416: gas temperature (T - T0)/(T_in - T0)
    at dimensionless depth xi = h a z / (rho_g c_g u_s) and time eta = h a (t - eps z / u_s)
    / ((1 - eps) rho_s c_s) in a bed at T0 fed with gas at T_in from t = 0, without axial
    conduction: 1 - int_0^xi exp(-s - eta) I0(2 sqrt(s eta)) ds (checked against a
    method-of-lines solution of the two equations to 1e-8 while writing this test)."""
    from scipy.integrate import quad
    from scipy.special import i0e
    if eta <= 0:
        return 0.0
    f = lambda s: np.exp(-s - eta + 2 * np.sqrt(s * eta)) * i0e(2 * np.sqrt(s * eta))
    return 1.0 - quad(f, 0.0, xi)[0]


def test_packed_bed_heated_by_hot_gas_breaks_through_as_schumann(tmp_path):
    """A simple-cubic bed of 192 touching 2 mm spheres (12 layers, one per fluid cell,
    eps = 1 - pi/6) held by walls, fed from t = 0 with gas at 400 K at 0.3 m/s through a 2 mm
    plenum; bed and gas at 300 K. Gunn's h (written out). The gas's heat capacity
    (15000 J/(kg K)) and the solid's (10 J/(kg K)) are chosen so that the bed is xi_L = 2.5
    long and breaks through in 0.17 s. The outlet temperature follows from the heat that
    entered through the fluid's boundaries, d/dt Q = rho_g c_g u_s A (T_in - T_out).
    Within 5 % of T_in - T0 of Schumann's solution over the whole curve but where the
    front arrives (|eta| < 0.5): there the solution jumps from 0 to exp(-xi_L) = 0.08, which a
    finite-volume gas smears over a few cells."""
    d, n, layers = 2e-3, 4, 12
    side, L, u, cp, cs, rho_s, plenum = n * d, layers * d, 0.3, 15000.0, 10.0, 2500.0, 2e-3
    axis = (np.arange(n) + 0.5) * d
    positions = [[x, y, (k + 0.5) * d] for k in range(layers) for y in axis.tolist() for x in axis.tolist()]
    walls = "\n".join(f'[[walls]]\nplane = "{p}"\nmaterial = "glass"' for p in ("zlo", "xlo", "xhi", "ylo", "yhi", "zhi"))
    scene = (SCENE.replace("box = [0.0, 0.04, 0.0, 0.04, 0.0, 0.04]", f"box = [0.0, {side}, 0.0, {side}, 0.0, {L}]\n"
                                                                        "gravity = [0.0, 0.0, 0.0]")
             .replace("cells = [{nx}, 1, 8]", f"cells = [1, 1, {layers + 1}]\nheat_capacity = {cp}\n"
                                                "inlet_temperature = 400.0\ntemperature = 300.0")
             .replace("heat_capacity = 1005.0\ntemperature = 400.0\n", "")
             .replace("youngs_modulus = 5e6", "youngs_modulus = 5e7")      # drag barely packs the bed
             .replace("dem_step = 1e-5", "dem_step = 5e-6")
             .replace("radius = 0.5e-3", "radius = 1e-3"))
    (tmp_path / "case.toml").write_text(scene.format(model="none", correlation="gunn", c=cs, count=len(positions),
                                                     where=f"positions = {positions}", spread=0.0, walls=walls, u=u,
                                                     couple=20, plenum=plenum, end=0.17, every=1.5e-3))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    with open(tmp_path / "out" / "history.csv") as f:
        rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
    eps, nu, k, rho_g = 1 - np.pi / 6, 1.8e-5 / 1.2, 0.026, 1.2
    Re, Pr = u * d / nu, nu * rho_g * cp / k
    nusselt = ((7 - 10 * eps + 5 * eps**2) * (1 + 0.7 * Re**0.2 * Pr ** (1 / 3))
               + (1.33 - 2.4 * eps + 1.2 * eps**2) * Re**0.7 * Pr ** (1 / 3))
    ha = nusselt * k / d * 6 * (1 - eps) / d
    xi = ha * L / (rho_g * cp * u)
    t = np.array([row["time"] for row in rows])
    Q = np.array([row["heat_through_fluid_boundaries"] for row in rows])
    rate = np.gradient(Q, t)
    theta_out = 1 - rate / (rho_g * cp * u * side**2 * 100.0)
    eta = ha * (t - plenum / u - eps * L / u) / ((1 - eps) * rho_s * cs)
    expected = np.array([schumann_gas(xi, e) for e in eta])
    error = np.abs(theta_out - expected)[np.abs(eta) > 0.5]
    print(f"xi_L {xi:.3f}, eta_end {eta[-1]:.2f}, theta_out end {theta_out[-1]:.4f} vs {expected[-1]:.4f}, "
          f"max error {error.max():.3%}")
    assert 1.5 < xi < 3 and eta[-1] > 5
    assert error.max() < 0.05


def test_gas_energy_on_one_and_two_ranks(tmp_path):
    """collheatFoam -energy alone: hot inlet, a wall at 500 K, 0.5 W into one cell, 50 steps.
    The gas's heat content changes by what entered through the boundaries plus the source,
    to 1e-10 (the pressure and T solvers' tolerances, summed over ranks); two ranks give
    the serial temperatures within 1e-3 K."""
    from pyhost.engines.fluid_case import box_case
    from pyhost.engines.openfoam import FluidSolver

    temperatures = {}
    for n in (1, 2):
        case = box_case(tmp_path / f"ranks{n}", lo=(0, 0, 0), hi=(0.02, 0.01, 0.05), cells=(4, 1, 10),
                        boundaries={"xlo": "wall", "xhi": "slip", "ylo": "slip", "yhi": "slip",
                                    "zlo": ("inlet", (0, 0, 0.5)), "zhi": "outlet"},
                        rho=1.2, nu=1.5e-5, gravity=(0, 0, 0), dt=1e-3, nprocs=n,
                        T0=300.0, T_inlet=400.0, T_walls={"xlo": 500.0})
        with FluidSolver(case, energy=True, nprocs=n) as fluid:
            before = np.sum(fluid.heat_capacity() * fluid.temperature())
            heat = np.zeros(len(fluid.cell_volumes))
            heat[np.argmin(np.linalg.norm(fluid.cell_centres - [0.01, 0.005, 0.02], axis=1))] = 0.5    # W
            for _ in range(50):
                fluid.advance(1e-3, heat=heat)
            T = fluid.temperature()
            after = np.sum(fluid.heat_capacity() * T)
            assert abs(after - before - fluid.boundary_heat - 0.5 * 0.05) < 1e-10 * after
            assert fluid.boundary_heat > 0.1                   # the hot inlet's enthalpy came in
            temperatures[n] = T[np.lexsort(np.round(fluid.cell_centres, 9).T)]
    assert np.abs(temperatures[1] - temperatures[2]).max() < 1e-3


FINE = """
[effects]
fluid = true

[materials.glass]
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.23
yield_stress = 500e6
heat_capacity = 840.0
conductivity = 1.0
dem = {{ youngs_modulus = 5e6, restitution = 0.9 }}

[[particles]]
material = "glass"
count = 1
radius = 1e-5
temperature = 300.0
positions = [[0.0005, 0.0005, 0.0015]]

[time]
dem_step = 1e-7
end = 2e-4
couple_every = {couple}

[fluid]                             # water, at rest
density = 1000.0
viscosity = 1e-3
inlet_velocity = 0.0
cells = [1, 1, 4]

[domain]
box = [0.0, 0.001, 0.0, 0.001, 0.0, 0.002]

[output]
vtk = false
pictures = false
"""


@pytest.mark.parametrize("couple", [100, 1000])
def test_drag_faster_than_the_coupling_interval_stops_the_run(tmp_path, couple):
    """A 20 um glass sphere in water: its drag relaxes its slip in m/K = rho_p d^2 / (18 mu) =
    5.6e-5 s (Stokes, at the start). Coupled every 1000 DEM steps of 0.1 us (0.1 ms), the
    host's drag, held over the interval, would carry it past the water's speed (K interval/m
    = 1.8): the run stops (exit 3) naming the particle and the interval to use, and its summary
    is written. Every 100 steps (K interval/m = 0.18) it runs."""
    (tmp_path / "case.toml").write_text(FINE.format(couple=couple))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    if couple == 100:
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        return
    assert r.returncode == 3, r.stdout[-3000:] + r.stderr[-3000:]
    tau = 2500.0 * (2e-5) ** 2 / (18 * 1e-3)
    assert "the gas's drag relaxes the slip of 1 particle(s) faster than the coupling interval of 0.0001 s" in r.stderr
    found = re.search(r"m/K = ([0-9.e+-]+) s, K interval/m = ([0-9.]+)\); .* couple at most every (\d+) DEM steps",
                      r.stderr)
    assert found, r.stderr
    relax, ratio, steps = float(found[1]), float(found[2]), int(found[3])
    print(f"m/K {relax:.4g} s (Stokes {tau:.4g} s), K interval/m {ratio}, couple every {steps} steps at most")
    assert relax == pytest.approx(tau, rel=0.02)             # Wen-Yu at Re ~ 1e-2 and alpha ~ 1: Stokes
    assert ratio == pytest.approx(1e-4 / relax, rel=0.01) and steps == int(relax / 1e-7)
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"].startswith("stopped at t = 0.0001 s by DragUnresolved")
