"""cases/bed-25k (the bed of DPMFoam's Goldschmidt tutorial) as a smoke run, engines for real."""
import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import pyvista
from scipy.optimize import brentq

pytestmark = pytest.mark.engines
CASE = Path(__file__).resolve().parents[2] / "cases" / "bed-25k"


def gidaspow_gradient(alpha, q, rho=1.2, mu=1.2e-5, d=2.5e-3):
    """Pressure gradient [Pa/m] across resting beads of diameter d [m] at fluid fraction alpha
    for superficial gas velocity q [m/s]: Gidaspow (1994) eqs. 5.49-5.50, Ergun below alpha =
    0.8, Wen-Yu with Schiller-Naumann above; -dp/dz = beta q / alpha^2."""
    u = q / alpha
    ergun = 150 * (1 - alpha) ** 2 * mu / (alpha * d**2) + 1.75 * (1 - alpha) * rho * u / d
    re = alpha * rho * u * d / mu
    cd = np.where(re < 1000, 24 / np.maximum(re, 1e-300) * (1 + 0.15 * re**0.687), 0.44)
    wen_yu = 0.75 * cd * alpha * (1 - alpha) * rho * u / d * alpha**-2.65
    return np.where(alpha < 0.8, ergun, wen_yu) * q / alpha**2


@pytest.mark.long
def test_bed_25k_smoke_keeps_its_beads_and_brackets_the_bed_drop(tmp_path):
    """-test (10 ms, 24,750 beads, about 25 s): no bead lost, energy balance exact, and the gas
    pressure drop across the still loose lattice between the two bounds of a heterogeneous
    resistive medium built from the solver's own cell fluid fractions (Gidaspow's law, 1.875
    m/s): the cell columns as parallel channels at one drop (lower bound: no crossflow) and
    every cell at the mean flux (upper bound: no redistribution), each with 3 % for the gas's
    own inertia and the beads' slow fall. Measured: 625 <= 689 <= 935 Pa."""
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(CASE), "--out", str(tmp_path), "--test"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["capped"] == 0 and summary["collisions"] > 0
    assert abs(summary["energy_balance_error"]) < 1e-12
    hist = list(csv.DictReader(open(tmp_path / "history.csv")))
    assert float(hist[-1]["time"]) == pytest.approx(0.01) and int(hist[-1]["particles"]) == 24750
    reader = pyvista.get_reader(str(tmp_path / "vtk" / "fluid.pvd"))
    reader.set_active_time_value(reader.time_values[-1])
    fluid = reader.read()[0]
    centres, alpha = np.round(fluid.points, 7), fluid.point_data["alpha"]
    axes = [np.unique(centres[:, k]) for k in range(3)]
    assert [len(a) for a in axes] == [2, 30, 91]
    grid = np.empty([len(a) for a in axes])
    grid[tuple(np.searchsorted(a, centres[:, k]) for k, a in enumerate(axes))] = alpha
    dz, q = 0.005, 1.875
    upper = gidaspow_gradient(grid, q).mean(axis=(0, 1)).sum() * dz
    columns = grid.reshape(-1, len(axes[2]))
    flux = lambda dp: np.mean([brentq(lambda u: gidaspow_gradient(c, u).sum() * dz - dp, 1e-9, 100) for c in columns])
    lower = brentq(lambda dp: flux(dp) - q, 1.0, 1e5)
    dp = float(hist[-1]["pressure_drop"])
    assert 0.97 * lower < dp < 1.03 * upper, (lower, dp, upper)
