"""The frozen-bed thermal stage and wall conduction on the real LIGGGHTS: a chain of three
held steel beads under a plate at 350 K, integrated at the DEM's steps by the lasting
conduction effect and by the frozen stage over the same window, both against the matrix
exponential of the same network; probes.csv written by both."""
import csv
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
R, OVERLAP = 3.2e-3, 2e-5          # m: the beads' radius, every contact's overlap (held: no integration)

SCRIPT = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.01 0.01 -0.01 0.01 0 0.03 units box
create_box 1 box
neighbor 0.001 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 200e9
fix m2 all property/global poissonsRatio peratomtype 0.29
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.8
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
hard_particles yes
pair_style gran model hertz tangential history
pair_coeff * *
fix plate all wall/gran model hertz tangential history primitive type 1 zplane {plate}
{atoms}
set group all diameter 0.0064 density 7747
timestep 0.05
{runs}
"""

SCENE = """[dem]
script = "in.liggghts"
[effects]
contact_conduction = "lethe"
[materials.steel]
types = [1]
temperature = 300.0
density = 7747.0
youngs_modulus = 200e9
poisson_ratio = 0.29
yield_stress = 1e9
heat_capacity = 464.0
conductivity = 42.0
[[walls]]
fix = "plate"
material = "steel"
temperature = 350.0
[output]
every = 1.0
vtk = false
pictures = false
probes = {{ top = [-0.01, 0.01, -0.01, 0.01, 0.015, 0.03], bottom = [-0.01, 0.01, -0.01, 0.01, 0.0, 0.008] }}
{frozen}
"""


def make(folder: Path, steps: int, frozen: str, runs: int = 1) -> Path:
    folder.mkdir()
    z = [0.005 + k * (2 * R - OVERLAP) for k in range(3)]      # three beads up, each contact's overlap OVERLAP
    plate = z[-1] + R - OVERLAP
    atoms = "\n".join(f"create_atoms 1 single 0 0 {zk!r} units box" for zk in z)
    runs = "\n".join([f"run {steps // runs}"] * runs)
    (folder / "in.liggghts").write_text(SCRIPT.format(plate=plate, atoms=atoms, runs=runs))
    (folder / "case.toml").write_text(SCENE.format(frozen=frozen))
    return folder


def run(case: Path):
    start = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(case / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    rows = list(csv.DictReader(open(case / "out" / "probes.csv")))
    probes = {k: np.array([float(row[k]) for row in rows]) for k in ("time", "top", "bottom")}
    return json.loads((case / "out" / "summary.json").read_text()), probes, time.perf_counter() - start


def exact(t):
    """The chain's temperatures [K] (bottom, middle, top) at t [s]: the lethe contact model's
    conductances of the held contacts (a = (R* delta)^(1/2), equal moduli), the plate a
    sphere of 1000 radii, integrated exactly."""
    C = 4 / 3 * np.pi * R**3 * 7747.0 * 464.0
    H = 2 * 42.0 * np.sqrt(R / 2 * OVERLAP)
    R_w = R * 1000 / 1001                      # R* of a bead against the plate
    H_w = 2 * 42.0 * np.sqrt(R_w * OVERLAP)
    A = np.array([[H, -H, 0], [-H, 2 * H, -H], [0, -H, H + H_w]]) / C
    return 350.0 + expm(-A * t) @ np.full(3, -50.0)


def test_frozen_stage_against_dem_step_integration(tmp_path):
    """Over 60 s (time constants 4.4 s to 105 s): the DEM-step integration (1200 steps of 0.05 s)
    and the frozen stage (20 DEM steps, then 1180 implicit steps of 0.05 s) agree with the exact
    curve within 0.05 K at every probe row (both first order: dt/tau_min = 1 %, of at most
    50 K gives 0.5 K at most, much less once the fast mode is gone) and with each other within
    0.05 K; the walls' heat closes the balance to 1e-12 in both; the frozen stage takes under
    2 s."""
    dem, p_dem, s_dem = run(make(tmp_path / "dem", 1200, ""))
    frz, p_frz, s_frz = run(make(tmp_path / "frozen", 20, "[frozen]\nend = 59.0\nstep = 0.05\nevery = 1.0"))
    for summary in (dem, frz):
        assert abs(summary["energy_balance_error"]) < 1e-12
        assert summary["heat_from_walls"] == pytest.approx(summary["heat_conducted_wall"], rel=1e-12)
        assert summary["heat_conducted_wall"] > 0
    assert frz["time"] == pytest.approx(60.0, rel=1e-12)
    assert frz["frozen_stage"]["wall_links"] == 1 and frz["frozen_stage"]["pairs_in_contact"] == 2
    # the probes: the top bead alone in 'top', the bottom bead in 'bottom'
    errs = {}
    for name, p in (("dem", p_dem), ("frozen", p_frz)):
        want = np.array([exact(t) for t in p["time"]])
        errs[name] = max(np.abs(p["top"] - want[:, 2]).max(), np.abs(p["bottom"] - want[:, 0]).max())
    both = np.intersect1d(np.round(p_dem["time"], 9), np.round(p_frz["time"], 9))
    pick = lambda p: np.isin(np.round(p["time"], 9), both)
    gap = max(np.abs(p_dem["top"][pick(p_dem)] - p_frz["top"][pick(p_frz)]).max(),
              np.abs(p_dem["bottom"][pick(p_dem)] - p_frz["bottom"][pick(p_frz)]).max())
    print(f"max |T - exact|: DEM steps {errs['dem']:.3g} K, frozen {errs['frozen']:.3g} K; between them {gap:.3g} K "
          f"at {len(both)} times; frozen stage {frz['frozen_stage']['wall_time']:.2f} s; runs {s_dem:.1f} s, {s_frz:.1f} s")
    assert p_frz["time"][-1] == pytest.approx(60.0) and len(both) >= 50
    assert errs["dem"] < 0.05 and errs["frozen"] < 0.05 and gap < 0.05
    assert frz["frozen_stage"]["wall_time"] < 2.0


def test_wall_heat_of_a_run_end_is_not_counted_again_at_the_next_run(tmp_path):
    """A script of two runs: the wall heat conducted at the end of the first (after the
    balance's last look) is not taken at the second run's start for heat the script set; the
    balance closes to 1e-12, and the heat and temperatures are those of one run of the same length
    (to the first-order effect of updating at other steps: 2.6e-5 of the heat)."""
    every = "[conduction]\nevery = 7"          # 300 steps a run: the last 6 conducted at the run's end
    two, p_two, _ = run(make(tmp_path / "two", 600, every, runs=2))
    one, p_one, _ = run(make(tmp_path / "one", 600, every))
    assert two["energy_set_by_script"] == 0.0
    assert abs(two["energy_balance_error"]) < 1e-12
    assert two["heat_conducted_wall"] == pytest.approx(one["heat_conducted_wall"], rel=1e-4)   # (2.6e-5: updates at other steps)
    assert p_two["top"][-1] == pytest.approx(p_one["top"][-1], abs=0.01)    # (updates at other steps)
