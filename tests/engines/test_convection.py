"""Gas energy and gas-particle convection on the real engines (collheatFoam -energy with
LIGGGHTS' Temp): one particle in a hot stream against the lumped solution, and the energy of
particles and gas together against what crossed the fluid's boundaries."""
import csv
import json
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
couple_every = 10

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
                        walls='[[walls]]\nplane = "zlo"\nmaterial = "glass"', u=u, plenum=0.01, nx=1,
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
                        u=1.0, plenum=0.0, nx=4, end=0.01, every=1e-4)
    total = np.array([r["sum_mcT"] + r["gas_energy"] - r["heat_through_fluid_boundaries"] - r["heat_from_walls"]
                      for r in rows])
    step = np.abs(np.diff(total)) / total[1:]
    print(f"{len(rows)} steps, largest change {step.max():.2e} of the total, heat convected "
          f"{rows[-1]['heat_convected']:.4g} J, collisions {summary['collisions']}")
    assert rows[-1]["heat_convected"] > 1e-3           # the exchange did work: about 4 mJ
    assert step.max() < 1e-9
    assert abs(summary["total_energy_balance_error"]) < 1e-9
    assert abs(summary["energy_balance_error"]) < 1e-12
