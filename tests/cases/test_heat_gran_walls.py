"""A script's fix heat/gran conducting from a hot wall, against plain LIGGGHTS: one glass sphere
dropped 0.1 mm onto a floor at 350 K (a primitive plane, ``fix wall/gran ... temperature 350.``,
or a mesh of two triangles, ``fix mesh/surface ... temperature 350.``, the sphere landing
off their common edge or on it, where LIGGGHTS conducts once; the plane also with the host on
two MPI ranks, with its temperature a variable, which LIGGGHTS evaluates, and with a constant contact
area), the
scene's [[walls]] giving the floor the same temperature for the models' collision heat. The
host takes back what heat/gran conducted through the wall contact during each collision's
model time t_coll (pyhost.effects.collisions.take_back_heat_gran); LIGGGHTS run alone, its
sphere's heatFlux dumped at every step, gives that share independently. The same against x, y
and z cylinders, walls defined after the script's first run, and one wall fix over a hot and
another mesh (its heat/gran conduction counted in the balance as LIGGGHTS conducts it)."""
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import FLOOR_STL, glass_toml, steel_toml

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

SCRIPT = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block 0 0.02 0 0.02 0 0.02 units box
create_box 1 box
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.8
fix m4 all property/global coefficientFriction peratomtypepair 1 0.3
fix m5 all property/global thermalConductivity peratomtype 1.0
fix m6 all property/global thermalCapacity peratomtype 840
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-6
fix gravi all gravity 9.81 vector 0 0 -1
{floor}
create_atoms 1 single {x} {y} 0.0011 units box
set group all diameter 0.002 density 2500
fix heattransfer all heat/gran initial_temperature 300.
fix integr all nve/sphere
{dump}run 5200
"""

SCENE = f"""[dem]
script = "in.drop"
[effects]
contact_heat = "A"
{glass_toml(temperature="temperature = 0.0")}
{steel_toml()}
[[walls]]
fix = "floor"
material = "steel"
temperature = 350.0
[output]
vtk = false
pictures = false
"""


FLOORS = {
    "primitive": "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0 temperature 350.",
    "primitive, ${Tw}": "variable Tw equal 300+50\n"
                        "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0 temperature ${Tw}",
    "primitive, constant area": "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0 "
                                "temperature 350. contact_area constant 2e-8",
    "mesh": "fix plate all mesh/surface file floor.stl type 1 move 0.01 0.01 0. temperature 350.\n"
            "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes plate",
}


@pytest.mark.parametrize("floor, ranks, at", [("primitive", 1, (0.006, 0.012)), ("mesh", 1, (0.006, 0.012)),
                                              ("mesh", 1, (0.01, 0.01)), ("primitive", 2, (0.006, 0.012)),
                                              ("primitive, ${Tw}", 1, (0.006, 0.012)),
                                              ("primitive, constant area", 1, (0.006, 0.012))])
def test_heat_grans_share_during_a_wall_collision_is_what_liggghts_conducted(floor, ranks, at, tmp_path):
    """The sphere's first impact (about 4,500 steps of 1 us down, v0 = 0.044 m/s, t_coll about 10 steps): heat/gran's share
    during t_coll, taken back by the host, equals plain LIGGGHTS' heatFlux into the sphere times
    dt over the contact's first t_coll / dt steps (the last one in part), to 1e-12 (it was
    compared with the Temp rises, whose differences near 300 K carry only about 1e-7 of it, with
    pytest.approx's default abs 1e-12 J: 2e-5 of it); the models' heat is moved instead
    (heat_from_walls > 0), and the balance closes to 1e-12."""
    native = tmp_path / "native"
    native.mkdir()
    (native / "floor.stl").write_text(FLOOR_STL)
    (native / "in.drop").write_text(SCRIPT.format(floor=FLOORS[floor], x=at[0], y=at[1], dump="dump t all custom 1 temp.dump id f_heatFlux[0]\n"
                                                           'dump_modify t format "%d %.17g"\n'))
    r = subprocess.run(["liggghts", "-in", "in.drop", "-screen", "/dev/null", "-log", "none"], cwd=native,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:]
    lines = (native / "temp.dump").read_text().splitlines()
    q = np.array([float(lines[k + 9].split()[1]) for k in range(0, len(lines), 10)])   # one atom: 10 lines a step
    first = int(np.flatnonzero(q)[0])     # heat/gran's flux into the sphere [W] at the end of each step from 0

    case = tmp_path / "host"
    case.mkdir()
    (case / "floor.stl").write_text(FLOOR_STL)
    (case / "in.drop").write_text(SCRIPT.format(floor=FLOORS[floor], x=at[0], y=at[1], dump=""))
    (case / "case.toml").write_text(SCENE)
    mpirun = ["mpirun", "--oversubscribe", "-np", str(ranks)] if ranks > 1 else []
    r = subprocess.run(mpirun + [sys.executable, "-m", "pyhost", "run", str(case), "--out", str(case / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600,
                       env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    summary = json.loads((case / "out" / "summary.json").read_text())
    with open(case / "out" / "collisions.csv") as f:
        rows = list(csv.DictReader(f))
    dt = 1e-6
    t_coll = float(rows[0]["t_coll"])
    share = np.clip(t_coll / dt - np.arange(len(q) - first), 0.0, 1.0)
    expected = dt * float(np.sum(q[first:] * share))
    print(f"{len(rows)} wall collisions, first at step {first}, v0 {float(rows[0]['v0']):.4f} m/s, t_coll "
          f"{t_coll:.3e} s; heat/gran in t_coll: LIGGGHTS {expected:.6e} J, taken back "
          f"{summary['heat_gran_walls_undone']:.6e} J; models' heat {summary['heat_from_walls']:.6e} J")
    assert len(rows) == 1 and abs(float(rows[0]["time"]) - first * dt) < 0.5 * dt
    assert 5.0 < t_coll / dt < 50.0 and expected > 0.0
    assert summary["heat_gran_walls_undone"] == pytest.approx(expected, rel=1e-12, abs=0.0)
    assert summary["heat_from_walls"] > 0.0
    assert abs(summary["energy_balance_error"]) < 1e-12


def test_a_sphere_resting_on_a_hot_floor_warms_by_enduring_conduction(tmp_path):
    """A box scene with enduring conduction: a 300 K steel sphere (R = 2 mm) settles on a 400 K
    floor and rests. heat/gran conducts from the floor through the lasting contact (its share
    during the landing collisions taken back), so the sphere warms as a lumped body through the
    static Hertz contact of the DEM's modulus: T = T_w - (T_w - T_0) exp(-h t / (m c)),
    h = 4 k k / (k + k) sqrt(A), A = pi (2 R delta - delta^2), delta = (3 m g / (4 E* R^1/2))^(2/3).
    Measured from 10 ms (settled) to 60 ms, within 0.1 % (measured: 0.299758 K both, to 1e-6 K);
    the balance closes. Before, a box wall
    gave heat/gran no temperature: the resting sphere did not warm at all."""
    case = tmp_path / "case"
    case.mkdir()
    text = (ROOT / "cases" / "wall-impact" / "case.toml").read_text()
    for old, new in [('contact_heat = "B"', 'contact_heat = "A"\nenduring_conduction = true'),
                     ("restitution_feedback = true", "restitution_feedback = false"),
                     ("restitution = 0.9", "restitution = 0.1"), ("temperature = 350.0", "temperature = 300.0"),
                     ("temperature = 300.0               # K, held fixed", "temperature = 400.0"),
                     ("velocity = [0.0, 0.0, -1.0]", "velocity = [0.0, 0.0, -0.05]"),
                     ("gravity = [0.0, 0.0, 0.0]", "gravity = [0.0, 0.0, -9.81]"),
                     ("dem_step = 1e-7", "dem_step = 1e-6"), ("end = 1e-3", "end = 0.06"),
                     ("test_end = 6e-4", "test_end = 0.06"), ("every = 1e-4", "every = 0.01\nvtk = false\npictures = false")]:
        assert old in text, old
        text = text.replace(old, new)
    (case / "case.toml").write_text(text)
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    with open(tmp_path / "out" / "history.csv") as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(row["time"]) for row in rows])
    T = np.array([float(row["T_group0"]) for row in rows])
    R, rho, c, k, E, nu, g = 2e-3, 7800.0, 470.0, 45.0, 2e8, 0.3, 9.81
    m = rho * 4.0 / 3.0 * np.pi * R**3
    E_star = 1.0 / (2.0 * (1.0 - nu**2) / E)
    delta = (3.0 * m * g / (4.0 * E_star * np.sqrt(R))) ** (2.0 / 3.0)
    h = 4.0 * k * k / (k + k) * np.sqrt(np.pi * (2.0 * R * delta - delta**2))
    a, b = np.searchsorted(t, 0.01 - 1e-9), len(t) - 1
    expected = 400.0 - (400.0 - T[a]) * np.exp(-h * (t[b] - t[a]) / (m * c))
    print(f"h = {h:.4e} W/K; T {T[a]:.6f} K at {t[a]:.3f} s -> {T[b]:.6f} K at {t[b]:.3f} s, lumped Hertz "
          f"{expected:.6f} K; heat/gran's share taken back {summary['heat_gran_walls_undone']:.3e} J, "
          f"balance {summary['energy_balance_error']:.2e}")
    assert T[b] - T[a] == pytest.approx(expected - T[a], rel=1e-3)
    assert summary["heat_gran_walls_undone"] > 0.0 and summary["particle_wall"] >= 1
    assert abs(summary["energy_balance_error"]) < 1e-12


CURVED = """{head}fix gravi all gravity 9.81 vector {g}
{wall}create_atoms 1 single {at} units box
set group all diameter 0.002 density 2500
{heat}fix integr all nve/sphere
run 10
{late}{dump}run 5190
"""
HEAT = "fix heattransfer all heat/gran initial_temperature 300.\n"
HEAD = SCRIPT.split("fix gravi")[0]
HOT = "fix tube all wall/gran model hertz tangential history primitive type 1 {} temperature 350.\n"
WALLS = {   # the wall, the pull towards it, where the sphere starts: 0.1 mm from it, moving at 0 m/s
    "zcylinder": ("zcylinder 0.009 0.01 0.01", "1 0 0", "0.0179 0.01 0.01"),
    "xcylinder": ("xcylinder 0.009 0.01 0.01", "0 1 0", "0.01 0.0179 0.01"),     # (R, y, z of the axis)
    "ycylinder": ("ycylinder 0.009 0.01 0.01", "0 0 -1", "0.01 0.01 0.0021"),    # (R, z, x of the axis)
    "zplane": ("zplane 0.0", "0 0 -1", "0.01 0.01 0.0011"),
}


def run_curved(tmp_path, wall, late, entry, ranks=1):
    """The sphere against ``wall`` (defined after the first run with ``late``, its fix heat/gran
    too with late = "both") in plain LIGGGHTS and in the host (with or without a
    [[walls]] entry at the wall's 350 K): (plain LIGGGHTS' Temp [K] and heat/gran's heatFlux
    into the sphere [W] at the end of every step, from 0, the host's summary, its collision
    rows, its output)."""
    primitive, g, at = WALLS[wall]
    fill = dict(head=HEAD, g=g, at=at, wall="" if late else HOT.format(primitive), heat="" if late == "both" else HEAT,
                late=(HEAT if late == "both" else "") + (HOT.format(primitive) if late else ""))
    native = tmp_path / "native"
    native.mkdir()
    (native / "in.drop").write_text(CURVED.format(**fill, dump="dump t all custom 1 temp.dump id f_Temp[0] f_heatFlux[0]\n"
                                                               'dump_modify t format "%d %.17g %.17g"\n'))
    r = subprocess.run(["liggghts", "-in", "in.drop", "-screen", "/dev/null", "-log", "none"], cwd=native,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:]
    lines = (native / "temp.dump").read_text().splitlines()
    assert lines[1] == "10"               # the dumps from step 10 on, before any contact
    T, q = np.array([[float(x) for x in lines[k + 9].split()[1:]] for k in range(0, len(lines), 10)]).T
    case = tmp_path / "host"
    case.mkdir()
    (case / "in.drop").write_text(CURVED.format(**fill, dump=""))
    scene = SCENE.replace('fix = "floor"', 'fix = "tube"')
    if late == "both":                    # the Temp the host adds at the first run: heat/gran's 300 K
        scene = scene.replace('temperature = 0.0\n', 'temperature = 300.0\n', 1)
    (case / "case.toml").write_text(scene if entry else scene.split("[materials.steel]")[0] + "[output]" + scene.split("[output]")[1])
    mpirun = ["mpirun", "--oversubscribe", "-np", str(ranks)] if ranks > 1 else []
    r = subprocess.run(mpirun + [sys.executable, "-m", "pyhost", "run", str(case), "--out", str(case / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600,
                       env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    with open(case / "out" / "collisions.csv") as f:
        rows = list(csv.DictReader(f))
    return T, q, json.loads((case / "out" / "summary.json").read_text()), rows, r.stdout


M_C = 2500.0 * 4.0 / 3.0 * np.pi * 0.001**3 * 840.0      # the sphere's m c [J/K]
DT = 1e-6


@pytest.mark.parametrize("wall, late, ranks", [("zcylinder", False, 1), ("zcylinder", True, 1), ("zplane", True, 1),
                                               ("zcylinder", "both", 1), ("zcylinder", True, 2)])
def test_heat_gran_through_a_cylinder_or_a_wall_defined_late_is_counted_as_liggghts_conducts_it(wall, late, ranks,
                                                                                                 tmp_path):
    """A sphere pulled against a hot wall (350 K) from 0.1 mm, 10 + 5,190 steps of 1 us: it touches
    it once (v0 = 0.044 m/s) and bounces off; the wall a zcylinder, or a wall defined after the
    script's first run (after the host's contact recorder: its heat/gran flux was added after
    the recorder summed the step's, and the run ended in exit 3, energy balance broken by the
    sphere's whole gain, 1.03e-5 J), or the wall and the fix heat/gran defined after it (the
    recorder did not follow a heat/gran that came after the first run: the same). No [[walls]] entry: the host changes no temperature, so its
    heat_from_script_walls is plain LIGGGHTS' sum of heatFlux dt over the steps, to 1e-12, and
    its m c (T_end - T_0) to 1e-10 (the dumped Temp near 300 K carries its 3.9 mK rise to about
    1e-11), and the sphere ends at plain LIGGGHTS' Temp; the late zcylinder on two MPI ranks too
    (each rank's recorder given anew after the wall)."""
    T, q, summary, rows, out = run_curved(tmp_path, wall, late, entry=False, ranks=ranks)
    conducted = DT * float(np.sum(q))
    print(f"{wall}{' after the first run' if late else ''}{', heat/gran too' if late == 'both' else ''}, {ranks} "
          f"rank(s): {len(rows)} wall collisions; plain LIGGGHTS: sum "
          f"heatFlux dt {conducted:.15e} J, m c dT {M_C * (T[-1] - T[0]):.15e} J; host heat_from_script_walls "
          f"{summary['heat_from_script_walls']:.15e} J, balance {summary['energy_balance_error']:.2e}")
    assert len(rows) == 1 and conducted > 1e-6
    assert summary["heat_from_script_walls"] == pytest.approx(conducted, rel=1e-12, abs=0.0)
    assert summary["heat_from_script_walls"] == pytest.approx(M_C * (T[-1] - T[0]), rel=1e-10, abs=0.0)
    assert summary["sum_mcT_end"] == pytest.approx(M_C * T[-1], rel=1e-15, abs=0.0)
    assert abs(summary["energy_balance_error"]) < 1e-12
    assert ("given anew after the script's walls" in out) == bool(late)


@pytest.mark.parametrize("wall", ["zcylinder", "xcylinder", "ycylinder"])
def test_heat_grans_share_during_a_cylinder_collision_is_what_liggghts_conducted(wall, tmp_path):
    """The same against each kind of cylinder, with a [[walls]] entry at 350 K: the models move
    the collision's heat, and heat/gran's share during its t_coll, taken back by the host, is
    plain LIGGGHTS' heatFlux dt over the contact's first t_coll / dt steps (the last in part;
    fix wall/gran's addHeatFlux: a cylinder's contact area is the sphere's cap,
    pi (R^2 - (R - delta)^2), as a plane's), to 1e-12; the balance closes to 1e-12."""
    _, q, summary, rows, _ = run_curved(tmp_path, wall, False, entry=True)
    first = int(np.flatnonzero(q)[0])
    t_coll = float(rows[0]["t_coll"])
    share = np.clip(t_coll / DT - np.arange(len(q) - first), 0.0, 1.0)
    expected = DT * float(np.sum(q[first:] * share))
    first += 10                                                     # the step (the dumps' first is 10)
    print(f"{wall}: {len(rows)} wall collisions, at step {first}, v0 {float(rows[0]['v0']):.4f} m/s, "
          f"t_coll {t_coll:.3e} s; heat/gran in t_coll: LIGGGHTS {expected:.15e} J; taken back "
          f"{summary['heat_gran_walls_undone']:.15e} J; balance {summary['energy_balance_error']:.2e}")
    assert len(rows) == 1 and abs(float(rows[0]["time"]) - first * DT) < 0.5 * DT
    assert 5.0 < t_coll / DT < 50.0 and expected > 0.0
    assert summary["heat_gran_walls_undone"] == pytest.approx(expected, rel=1e-12, abs=0.0)
    assert summary["heat_from_walls"] > 0.0
    assert abs(summary["energy_balance_error"]) < 1e-12


MESHES = """{head}fix gravi all gravity 9.81 vector 0 0 -1
fix floor all mesh/surface file floor.stl type 1 move 0.01 0.01 0. {floor}
fix roof all mesh/surface file floor.stl type 1 move 0.01 0.01 0.019 {roof}
fix plates all wall/gran model hertz tangential history mesh n_meshes 2 meshes floor roof
create_atoms 1 single 0.006 0.012 0.0011 units box
create_atoms 1 single 0.014 0.008 0.0179 units box
set group all diameter 0.002 density 2500
group up id 2
velocity up set 0 0 0.1
fix heattransfer all heat/gran initial_temperature 300.
fix integr all nve/sphere
{dump}run 5200
"""


@pytest.mark.parametrize("roof, entry", [("", True), ("temperature 320.", False), ("temperature 320.", True)])
def test_one_wall_fix_over_a_hot_and_another_mesh(roof, entry, tmp_path):
    """One fix wall/gran over two meshes (LIGGGHTS 3.8 takes no second mesh wall fix): a floor at
    350 K and a roof with no temperature or at 320 K; sphere 1 falls onto the floor (step 4516),
    sphere 2 thrown up at 0.1 m/s hits the roof (about 1 ms). Plain LIGGGHTS conducts through
    each mesh at its own temperature (fix wall/gran's addHeatFlux reads each mesh's). A [[walls]]
    entry at 350 K over a floor at 350 K and a roof without one runs: both collisions get the
    models' heat from 350 K, and heat/gran's share is taken back where it conducts, the floor's
    collision: plain LIGGGHTS' heatFlux dt over its t_coll, to 1e-12. No entry, roof at 320 K:
    heat_from_script_walls is plain LIGGGHTS' sum of both spheres' heatFlux dt, to 1e-12. An
    entry at 350 K with the roof at 320 K: refused before the first step naming the fix and
    both meshes' temperatures. Every balance to 1e-12."""
    from conftest import FLOOR_STL as STL
    fill = dict(head=HEAD, floor="temperature 350.", roof=roof)
    native = tmp_path / "native"
    native.mkdir()
    (native / "floor.stl").write_text(STL)
    (native / "in.mesh").write_text(MESHES.format(**fill, dump="dump t all custom 1 temp.dump id f_heatFlux[0]\n"
                                                                'dump_modify t format "%d %.17g" sort id\n'))
    r = subprocess.run(["liggghts", "-in", "in.mesh", "-screen", "/dev/null", "-log", "none"], cwd=native,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-2000:]
    lines = (native / "temp.dump").read_text().splitlines()
    q = np.array([[float(lines[k + 9 + a].split()[1]) for a in (0, 1)] for k in range(0, len(lines), 11)])
    case = tmp_path / "host"
    case.mkdir()
    (case / "floor.stl").write_text(STL)
    (case / "in.mesh").write_text(MESHES.format(**fill, dump=""))
    scene = SCENE.replace('"in.drop"', '"in.mesh"').replace('fix = "floor"', 'fix = "plates"')
    (case / "case.toml").write_text(scene if entry else scene.split("[materials.steel]")[0] + "[output]" + scene.split("[output]")[1])
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(case / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    if roof and entry:
        assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
        assert ("walls[0].temperature: 350 K, where the script gives wall 'plates' 320 K" in r.stderr
                and "its meshes: floor 350 K, roof 320 K" in r.stderr), r.stderr[-2000:]
        return
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    summary = json.loads((case / "out" / "summary.json").read_text())
    with open(case / "out" / "collisions.csv") as f:
        rows = list(csv.DictReader(f))
    assert [(row["i"], row["wall"]) for row in rows] == [("2", "2"), ("1", "1")]      # roof, then floor
    assert abs(summary["energy_balance_error"]) < 1e-12
    if entry:
        first = int(np.flatnonzero(q[:, 0])[0])
        share = np.clip(float(rows[1]["t_coll"]) / DT - np.arange(len(q) - first), 0.0, 1.0)
        expected = DT * float(np.sum(q[first:, 0] * share))
        print(f"floor's collision at step {first}: heat/gran in t_coll {expected:.15e} J, taken back "
              f"{summary['heat_gran_walls_undone']:.15e} J; the roof conducted {DT * np.sum(q[:, 1]):g} J")
        assert not q[:, 1].any() and "not through roof (no temperature in the script)" in r.stdout
        assert summary["heat_gran_walls_undone"] == pytest.approx(expected, rel=1e-12, abs=0.0)
        assert summary["heat_from_walls"] > 0.0 and float(rows[0]["Q"]) != 0.0      # the roof's: from 350 K
    else:
        conducted = DT * float(np.sum(q))
        print(f"heatFlux dt summed: floor {DT * np.sum(q[:, 0]):.6e} J, roof {DT * np.sum(q[:, 1]):.6e} J; host "
              f"{summary['heat_from_script_walls']:.15e} J, LIGGGHTS {conducted:.15e} J")
        assert q[:, 1].any() and summary["heat_from_script_walls"] == pytest.approx(conducted, rel=1e-12, abs=0.0)
