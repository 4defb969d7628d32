"""``python -m pyhost post`` on the dumps of a real LIGGGHTS pour (marked engines), and on bad input."""
import csv
import gzip
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import steel_toml
import pyvista

from pyhost.scene import load_post_scene
from pyhost.scene import SceneError

ROOT = Path(__file__).resolve().parents[2]
GLASS = """[materials.glass]
types = [1, 2]
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.22
yield_stress = 500e6
heat_capacity = 800.0
conductivity = 1.0
dem = { youngs_modulus = 5e6, restitution = 0.8, poisson_ratio = 0.3 }
"""
STEEL_WALL = "\n" + steel_toml() + """
[[walls]]
fix = "walls"
material = "steel"
temperature = 350.0
"""


def post(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "pyhost", "post", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def rows(out):
    with gzip.open(out / "collisions.csv.gz", "rt") as f:
        return list(csv.DictReader(f))


def first_appearances(files, key):
    """Contacts new in each frame of a dump local, counted with plain Python from the rows."""
    files = sorted(files, key=lambda p: int(p.name.split(".")[-1]))
    previous, count = set(), 0
    for path in files:
        lines = path.read_text().splitlines()
        current = {key(line.split()) for line in lines[9:]}
        count += len(current - previous)
        previous = current
    return count


@pytest.mark.engines
@pytest.mark.parametrize("told", ["script", "options"])
def test_collision_counts_match_an_independent_count_of_the_contact_dumps(pour_dumps, tmp_path, told):
    """The computes' keywords and dt from the script, or from options (typed as in the script)."""
    (tmp_path / "scene.toml").write_text(GLASS + STEEL_WALL)
    post_dir = pour_dumps / "post"
    how = (["--script", pour_dumps / "in.pour"] if told == "script" else
           ["--dt", "1e-5", "--compute", "cp pair/gran/local delta id vel pos", "--compute",
            "cw wall/gran/local vel id pos delta"])
    run = post(post_dir / "dump.*", "--scene", tmp_path / "scene.toml", "--contacts", post_dir / "pair.*",
               post_dir / "wall.*", *how, "--out", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    # columns of 'delta id vel pos' in LIGGGHTS' order (ENGINES.md): pair ids 13, 14; wall mesh 13, id 15
    pairs = first_appearances(post_dir.glob("pair.*"), lambda w: frozenset((w[12], w[13])))
    walls = first_appearances(post_dir.glob("wall.*"), lambda w: (w[12], w[14]))
    print(f"collisions: {summary['collisions']}, independent count: {pairs} pair, {walls} wall")
    assert summary["complete"] is True and summary["frames"] == 13 and summary["particles"] == 60
    assert summary["collisions"] == {"particle_particle": pairs, "particle_wall": walls}
    assert pairs > 50 and walls > 20
    table = rows(tmp_path / "out")
    assert len(table) == pairs + walls
    wall = np.array([r["wall"] != "0" for r in table])
    for model in "ABC":
        Q = np.array([float(r[f"Q_{model}"]) for r in table])
        # every particle starts at LIGGGHTS' 300 K (f_Temp) and stays below the 350 K wall: heat goes in
        assert np.all(Q[wall] < 0.0) and np.abs(Q[~wall]).sum() > 0
        assert summary["heat_J"][model] == pytest.approx(np.abs(Q).sum(), rel=1e-12)
    # heat balance over the last frame (the run's end): what the particles gained is what the wall gave;
    # collisions between particles move heat among them and cancel
    reader = pyvista.get_reader(str(tmp_path / "out" / "vtk" / "particles.pvd"))
    reader.set_active_time_value(reader.time_values[-1])
    last = reader.read()[0]
    C = 4 / 3 * np.pi * last["radius"] ** 3 * 2500.0 * 800.0
    Q = np.array([float(r["Q_A"]) for r in table])
    assert np.sum(C * last["dT_A"]) == pytest.approx(-Q[wall].sum(), rel=1e-9)
    # per particle too; dT = T - T0 near 300 K carries about 1e-13 K of rounding, C < 0.03 J/K
    assert np.allclose(last["heat_A"], C * last["dT_A"], rtol=1e-9, atol=1e-14)
    assert (tmp_path / "out" / "post.png").stat().st_size > 10_000


@pytest.mark.engines
def test_the_dem_contact_comes_from_the_script(pour_dumps, tmp_path):
    """With --script, post reads the DEM's moduli, Poisson ratios and restitutions from the
    script's fix property/global (the particles' types and the mesh wall's type 1), as a run
    reads them from the engine: a scene without dem tables gives the same collisions and heat,
    to the last digit, as one whose tables state the script's values; a table that disagrees
    is refused (exit 2) naming both."""
    post_dir = pour_dumps / "post"
    scenes = {"tables": GLASS + STEEL_WALL,
              "none": "\n".join(ln for ln in (GLASS + STEEL_WALL).splitlines() if not ln.startswith("dem = ")),
              "other": (GLASS + STEEL_WALL).replace("restitution = 0.8", "restitution = 0.5", 1)}
    runs = {}
    for name, text in scenes.items():
        (tmp_path / f"{name}.toml").write_text(text)
        runs[name] = post(post_dir / "dump.*", "--scene", tmp_path / f"{name}.toml", "--contacts", post_dir / "pair.*",
                          post_dir / "wall.*", "--script", pour_dumps / "in.pour", "--out", tmp_path / name)
    assert runs["tables"].returncode == 0 and runs["none"].returncode == 0, runs["none"].stderr
    table, none = rows(tmp_path / "tables"), rows(tmp_path / "none")
    assert len(table) > 70 and table == none
    assert runs["other"].returncode == 2
    assert ("materials.glass.dem.restitution = 0.5 differs from the script's coefficientRestitution 0.8 of atom "
            "type 1") in runs["other"].stderr


@pytest.mark.engines
def test_positions_alone_find_the_pairs_liggghts_listed_and_warn_about_a_long_interval(pour_dumps, tmp_path):
    """From positions dumped every 20 steps (the contact dumps' interval), the particle pairs are
    those of LIGGGHTS' own contact list; from dumps every 500 steps most are missed, and the
    command says why with the numbers."""
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1, 2]\ntemperature = 300"))
    post_dir = pour_dumps / "post"
    pairs = first_appearances(post_dir.glob("pair.*"), lambda w: frozenset((w[12], w[13])))
    fine = post(post_dir / "fine.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-5", "--out", tmp_path / "fine",
                "--model", "B")
    assert fine.returncode == 0, fine.stderr
    found = json.loads((tmp_path / "fine" / "summary.json").read_text())["collisions"]["particle_particle"]
    print(f"from positions every 20 steps: {found}; LIGGGHTS' contact list: {pairs}")
    assert abs(found - pairs) <= 0.02 * pairs          # %g positions: overlaps within 1e-7 m may differ
    coarse = post(post_dir / "dump.*", "--scene", tmp_path / "scene.toml", "--dt", "1e-5", "--out", tmp_path / "coarse")
    assert coarse.returncode == 0, coarse.stderr
    summary = json.loads((tmp_path / "coarse" / "summary.json").read_text())
    assert summary["collisions"]["particle_particle"] < pairs / 2
    [warning] = [w for w in summary["warnings"] if "dump interval" in w]
    assert "0.005 s (500 steps) exceeds the shortest DEM collision time" in warning
    assert summary["shortest_collision_s"] < summary["dump_interval_s"] == pytest.approx(5e-3)


HEAD = "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 0.01\n0 0.01\n0 0.01\n" \
       "ITEM: ATOMS id type x y z vx vy vz radius \n"


def test_a_failure_keeps_what_came_before_and_says_incomplete(tmp_path):
    """Two spheres meet between frames 0 and 1; frame 2 is cut. Exit 2 with file, timestep and
    line; the collision before the cut is on disk and summary.json says incomplete."""
    frames = [(0, 0.0040, 0.0060), (10, 0.00450005, 0.00549995)]           # then 0.1 um of overlap
    text = "".join(HEAD.format(step=s) + f"1 1 {a} 0.005 0.005 0.1 0 0 0.0005 \n2 1 {b} 0.005 0.005 -0.1 0 0 0.0005 \n"
                   for s, a, b in frames)
    text += HEAD.format(step=20) + "1 1 0.0045 0.005 0.005 0.1 0 0 0.0005 \n"
    (tmp_path / "run.dump").write_text(text)
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1]\ntemperature = 300"))
    run = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--out", tmp_path / "out")
    assert run.returncode == 2
    assert run.stderr.strip().splitlines() == [f"error: {tmp_path / 'run.dump'}: line 33: timestep 20: "
                                               "file ends after 1 rows of 2 (truncated)"]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["complete"] is False and "truncated" in summary["error"]
    [row] = rows(tmp_path / "out")
    assert (row["i"], row["j"], float(row["time"])) == ("1", "2", pytest.approx(1e-5))
    assert 0.2 < float(row["v0"]) < 0.2 * 1.01       # approach 0.2 m/s, slowed a little by that overlap
    skip = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--out", tmp_path / "skip",
                "--skip-bad-frames")
    assert skip.returncode == 0, skip.stderr
    summary = json.loads((tmp_path / "skip" / "summary.json").read_text())
    assert summary["complete"] is False and summary["skipped"] == 1     # a frame was skipped: not the whole run
    assert summary["frames"] == 2 and len(rows(tmp_path / "skip")) == 1
    assert any("skipped" in w and "timestep 20" in w and "line 33" in w for w in summary["warnings"])


def test_contacts_open_in_the_first_frame_are_not_collisions(tmp_path):
    """Dumps that begin mid-run (a settled bed, a restart): a pair resting in contact in the
    first frame began before the record and is not a collision (integrated back, its static
    overlap alone gave it an impact at 5.3e-4 m/s and 4.6e-10 J from the hot sphere to the
    cold one); a pair that meets between the frames is one, at its 0.2 m/s."""
    head = HEAD.replace("NUMBER OF ATOMS\n2", "NUMBER OF ATOMS\n4")
    rest = "1 1 0.002 0.005 0.005 0 0 0 0.0005 \n2 2 0.0029999 0.005 0.005 0 0 0 0.0005 \n"   # 0.1 um overlap
    frames = [(0, 0.0060, 0.0080), (10, 0.00650005, 0.00749995)]
    (tmp_path / "run.dump").write_text("".join(
        head.format(step=s) + rest + f"3 1 {a} 0.005 0.005 0.1 0 0 0.0005 \n4 2 {b} 0.005 0.005 -0.1 0 0 0.0005 \n"
        for s, a, b in frames))
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1, 2]\ntemperature = [400, 300]"))
    run = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--out", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["contacts_open_at_start"] == 1 and summary["collisions"]["particle_particle"] == 1
    assert any("1 contacts are open in the first frame of run.dump (timestep 0)" in w for w in summary["warnings"])
    [row] = rows(tmp_path / "out")
    assert (row["i"], row["j"]) == ("3", "4") and 0.2 < float(row["v0"]) < 0.2 * 1.01


def hot_and_cold(tmp_path, hot_from: int) -> None:
    """run.dump: two glass spheres approaching at 0.1 m/s each, meeting between steps 10 and 20;
    sphere 2 dumped at 250 K, sphere 1 at 300 K until step ``hot_from``, then at 400 K; and
    scene.toml, its material taking the dumped temperatures."""
    head = HEAD.replace("radius \n", "radius f_Temp\n")
    frames = [(0, 0.0040, 0.0060), (10, 0.0042, 0.0058), (20, 0.00450005, 0.00549995)]
    (tmp_path / "run.dump").write_text("".join(
        head.format(step=s) + f"1 1 {a} 0.005 0.005 0.1 0 0 0.0005 {400 if s >= hot_from else 300}\n"
        f"2 1 {b} 0.005 0.005 -0.1 0 0 0.0005 250\n" for s, a, b in frames))
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1]"))


def test_a_scripts_set_of_temperatures_is_followed(tmp_path):
    """A script that sets particles' Temp between runs (Debian's heatTransfer tutorials heat half
    their bed after it settles): post's temperatures change by what the dumps' temperature
    changed across the set, so a pair meeting after it moves heat from 400 K to 250 K: three times
    what the same dumps give without the set (particle 1 kept its first appearance's 300 K); two
    sets between the same frames change the temperatures once; a set before the first run is
    in the first frame already."""
    script = tmp_path / "in.heat"
    script.write_text("timestep 1e-6\nset atom 2 property/atom Temp 250\nrun 10 upto\n"
                      "set atom 1 property/atom Temp 400 # the hot one\nset atom 2 property/atom Temp 250\n"
                      "run 20 upto\n")
    hot_and_cold(tmp_path, hot_from=20)
    run = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--script", script, "--out", tmp_path / "out")
    assert run.returncode == 0, run.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    [done] = summary["temperature_sets"]
    assert (done["steps"], done["frames"], done["particles_changed"], done["mean_change_K"]) == ([10, 10], [10, 20],
                                                                                                 1, 100.0)
    assert done["commands"][0].endswith("in.heat: line 4: set atom 1 property/atom Temp 400")
    [row] = rows(tmp_path / "out")
    assert (row["i"], row["j"], float(row["time"])) == ("1", "2", pytest.approx(2e-5)) and float(row["Q_A"]) > 0
    assert summary["heat_J"]["A"] == pytest.approx(float(row["Q_A"]))
    script.write_text("timestep 1e-6\nset atom 2 property/atom Temp 250\nrun 10 upto\nrun 20 upto\n")   # no set
    unset = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--script", script, "--out", tmp_path / "b")
    assert unset.returncode == 0, unset.stderr
    assert float(row["Q_A"]) == pytest.approx(3.0 * float(rows(tmp_path / "b")[0]["Q_A"]), rel=1e-9)


def test_temperatures_from_the_dumps(tmp_path):
    """--temperatures dumps: at every frame each particle takes its dumped temperature (a run's
    own conduction or heat sources raised particle 1 from 300 K to 400 K, which post's own
    temperatures never see), so the pair meeting after that frame moves heat from 400 K to
    250 K: three times what the default gives; dumps without a temperature are refused."""
    hot_and_cold(tmp_path, hot_from=10)
    Q = {}
    for mode in ("own", "dumps"):
        r = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--temperatures", mode,
                 "--out", tmp_path / mode)
        assert r.returncode == 0, r.stderr
        [row] = rows(tmp_path / mode)
        Q[mode] = float(row["Q_A"])
        assert json.loads((tmp_path / mode / "summary.json").read_text())["temperatures"] == mode
    assert Q["own"] > 0 and Q["dumps"] == pytest.approx(3.0 * Q["own"], rel=1e-9)
    (tmp_path / "cold.dump").write_text((tmp_path / "run.dump").read_text().replace(" f_Temp\n", "\n")
                                        .replace(" 300\n", "\n").replace(" 400\n", "\n").replace(" 250\n", "\n"))
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1]\ntemperature = 300"))
    r = post(tmp_path / "cold.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--temperatures", "dumps",
             "--out", tmp_path / "cold")
    assert r.returncode == 2 and "--temperatures dumps: the frame has no particle temperature (f_Temp)" in r.stderr


@pytest.mark.parametrize("change, problem", [
    (lambda s: s.replace("types = [1, 2]", "types = [1, 0]"), "types: atom types are integers >= 1"),
    (lambda s: s + STEEL_WALL.replace('fix = "walls"', 'fix = "walls"\nplane = "zlo"'), "give either fix"),
    (lambda s: s + STEEL_WALL.replace("types", "x").replace('material = "steel"', 'material = "wood"'),
     "unknown material 'wood'"),
    (lambda s: s.replace("types = [1, 2]", "types = [1, 2]\ntemperature = -3"), "temperature: must be"),
    (lambda s: s.replace("density", "densty"), "densty: unknown key"),
    (lambda s: s.replace("types = [1, 2]", "types = [1, 2]\ntemperature = [300.0]"), "1 temperatures for 2 types"),
])
def test_scene_errors_name_the_key(tmp_path, change, problem):
    (tmp_path / "s.toml").write_text(change(GLASS))
    with pytest.raises(SceneError, match=problem):
        load_post_scene(tmp_path / "s.toml")


def test_a_temperature_per_type(tmp_path):
    (tmp_path / "s.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1, 2]\ntemperature = [400, 300.5]"))
    assert load_post_scene(tmp_path / "s.toml").temperature == {1: 400.0, 2: 300.5}


def test_an_atom_type_without_material_is_an_error(tmp_path):
    (tmp_path / "d").write_text(HEAD.format(step=0) + "1 3 0.004 0.005 0.005 0 0 0 0.0005 \n"
                                "2 1 0.006 0.005 0.005 0 0 0 0.0005 \n")
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1]\ntemperature = 300"))
    run = post(tmp_path / "d", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--out", tmp_path / "out")
    assert run.returncode == 2 and "atom type 3 is in no material" in run.stderr


@pytest.mark.engines
def test_offline_agrees_with_the_online_run(pour_dumps, tmp_path):
    """The pour run by the host (``pyhost run``: contact events recorded inside LIGGGHTS) and
    the same script's own dumps post-processed with its contacts dumped at every step (post
    takes a contact's first appearance as its collision and carries its approach speed back to
    touch with the DEM's law): the same collisions at the same steps (the host's pour is plain
    LIGGGHTS' to the bit: 177 particle and 78 wall collisions, measured). Post's impact speeds,
    integrated back with a two-body law from the end of the first step in contact, against the
    recorder's at touch: median 1.3e-3 apart, at most 7 % (particles touching others at once,
    whose forces that law leaves out), measured; asserted 3e-3 and 0.1. The heat between
    particles and from the walls to 1e-3 (measured 1.8e-4 for the walls)."""
    for name in ("in.pour", "floor.stl"):
        (tmp_path / name).write_text((pour_dumps / name).read_text())
    (tmp_path / "post").mkdir()
    (tmp_path / "case.toml").write_text('[dem]\nscript = "in.pour"\n\n[effects]\ncontact_heat = "A"\n\n'
                                        + GLASS + STEEL_WALL + "\n[output]\npictures = false\n")
    online = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(tmp_path / "online")],
                            capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert online.returncode == 0, online.stdout[-2000:] + online.stderr[-2000:]
    offline = post(tmp_path / "post" / "dump.*", "--scene", tmp_path / "case.toml", "--contacts",
                   pour_dumps / "post" / "pairs_every_step.dump", pour_dumps / "post" / "walls_every_step.dump",
                   "--script", tmp_path / "in.pour", "--model", "A", "--out", tmp_path / "offline")
    assert offline.returncode == 0, offline.stderr
    run = json.loads((tmp_path / "online" / "summary.json").read_text())
    done = json.loads((tmp_path / "offline" / "summary.json").read_text())
    print({k: run.get(k) for k in ("particle_particle", "particle_wall", "contacts_without_impact")}, done["collisions"])
    with open(tmp_path / "online" / "collisions.csv") as f:
        on = {(round(float(r["time"]), 9), frozenset((r["i"], r["j"], r["wall"]))): r for r in csv.DictReader(f)}
    off = {(round(float(r["time"]), 9), frozenset((r["i"], r["j"], r["wall"]))): r for r in rows(tmp_path / "offline")}
    assert len(on) > 200 and set(on) <= set(off)
    assert len(off) - len(on) == run.get("contacts_without_impact", 0)
    keys = sorted(on, key=str)
    v_on, v_off = (np.array([float(d[k]["v0"]) for k in keys]) for d in (on, off))
    Q_on = np.array([float(on[k]["Q"]) for k in keys])
    Q_off = np.array([float(off[k]["Q_A"]) for k in keys])
    wall = np.array([on[k]["wall"] != "0" for k in keys])
    rel = np.abs(v_off / v_on - 1)
    print(f"v0: median relative difference {np.median(rel):.2g}, max {rel.max():.2g}; wall heat "
          f"{-Q_off[wall].sum():.6g} J offline, {-Q_on[wall].sum():.6g} J online")
    assert np.median(rel) < 3e-3 and rel.max() < 0.1
    assert -Q_off[wall].sum() == pytest.approx(run["heat_from_walls"], rel=1e-3)
    assert np.abs(Q_off[~wall]).sum() == pytest.approx(np.abs(Q_on[~wall]).sum(), rel=1e-3)


@pytest.mark.parametrize("files, named", [(("scene.json",), "scene.json"),
                                          (("history.csv", "collisions.csv"), "collisions.csv"),
                                          (("collisions/schema.json",), "collisions"),
                                          ((), "summary.json with a status")],
                         ids=["scene.json", "no scene.json", "binary log", "summary only"])
def test_out_holding_a_run_is_refused(tmp_path, files, named):
    """post writes a summary.json of its own: pointed at a run's output folder, it refuses
    instead of replacing the run's summary, whatever marks the folder as a run's. A run's
    folder without scene.json (an older run's, one stopped on a full disk) was written over.
    post's own folder it writes again."""
    (tmp_path / "scene.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1, 2]\ntemperature = 300"))
    (tmp_path / "run").mkdir()
    for name in files:
        (tmp_path / "run" / name).parent.mkdir(exist_ok=True)
        (tmp_path / "run" / name).write_text("{}")
    (tmp_path / "run" / "summary.json").write_text('{"status": "completed"}')
    (tmp_path / "d.dump").write_text(HEAD.format(step=0) + "1 1 0.005 0.005 0.005 0 0 0 0.001\n"
                                     "2 1 0.002 0.002 0.002 0 0 0 0.001\n")
    r = post(tmp_path / "d.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-5", "--out", tmp_path / "run")
    assert r.returncode == 2 and f"holds the output of a run ({named})" in r.stderr, r.stderr
    assert json.loads((tmp_path / "run" / "summary.json").read_text()) == {"status": "completed"}
    for again in range(2):
        r = post(tmp_path / "d.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-5", "--out", tmp_path / "own")
        assert r.returncode == 0, r.stderr


@pytest.mark.engines
@pytest.mark.parametrize("particles", ["dump.*", "fine.dump"])
def test_contact_dumps_of_another_run_are_refused(pour_dumps, tmp_path, particles):
    """The same pour with another insertion seed: its contact dumps have the same ids and
    steps, so they used to be taken for the first run's. Their particles are elsewhere than
    in the particle dumps at the same step: refused (exit 2) naming the file and step. With
    the particle dumps every 20 steps (fine.dump) they were still accepted: only the first 8
    particle frames (steps 0 to 140) were kept to check against, before any contact."""
    other = tmp_path / "other"
    (other / "post").mkdir(parents=True)
    (other / "floor.stl").write_text((pour_dumps / "floor.stl").read_text())
    script = (pour_dumps / "in.pour").read_text().replace("seed 49979687", "seed 86028121")
    assert script != (pour_dumps / "in.pour").read_text()
    (other / "in.pour").write_text(script)
    done = subprocess.run(["liggghts", "-in", "in.pour", "-log", "log.liggghts", "-screen", "/dev/null"], cwd=other,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, (other / "log.liggghts").read_text()[-2000:]
    glass = GLASS if particles == "dump.*" else GLASS.replace("types = [1, 2]", "types = [1, 2]\ntemperature = 300")
    (tmp_path / "scene.toml").write_text(glass + STEEL_WALL)       # (fine.dump holds no f_Temp)
    run = post(pour_dumps / "post" / particles, "--scene", tmp_path / "scene.toml", "--contacts",
               other / "post" / "pair.*", "--script", pour_dumps / "in.pour", "--out", tmp_path / "out")
    assert run.returncode == 2, run.stderr
    assert "the contact dumps are not of the run the particle dumps are of" in run.stderr
    assert f"{other / 'post' / 'pair.'}" in run.stderr and "timestep" in run.stderr
    same = post(pour_dumps / "post" / particles, "--scene", tmp_path / "scene.toml", "--contacts",
                pour_dumps / "post" / "pair.*", "--script", pour_dumps / "in.pour", "--out", tmp_path / "same")
    assert same.returncode == 0, same.stderr
    assert not any("is not checked" in w for w in json.loads((tmp_path / "same" / "summary.json").read_text())["warnings"])


def test_progress_lines_on_a_long_job(tmp_path, capsys):
    """post says where it is while it reads and replays the dumps (every 5 s of wall time by
    default; here at every frame): the dump time reached and the collisions found, then moved."""
    from pyhost.post import Post

    hot_and_cold(tmp_path, hot_from=10)
    Post([tmp_path / "run.dump"], load_post_scene(tmp_path / "scene.toml"), tmp_path / "out", dt=1e-6,
         progress_every=0.0).run()
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split(";")[1].strip() for ln in lines] == \
        ["reading the dumps: frame 1, 0 collisions found", "reading the dumps: frame 2, 0 collisions found",
         "reading the dumps: frame 3, 0 collisions found", "replaying the dumps: heat of 0 of 1 collisions moved",
         "replaying the dumps: heat of 0 of 1 collisions moved", "replaying the dumps: heat of 0 of 1 collisions moved"]
    assert lines[2].startswith("t = 2e-05 s")


@pytest.mark.engines
def test_contact_dumps_written_per_processor_are_read(tmp_path):
    """The pour on 2 MPI ranks with its contact dumps one file per step and processor
    ('post/pair.*.%'): LIGGGHTS writes the header, with processor 0's row count, into
    processor 0's file only, the other's file holds bare rows (or nothing). post refused
    them ('not a dump local of a compute: '''); it reads each step's files as one frame: the
    collisions are the first appearances counted with plain Python over both processors'
    rows of each step (pairs listed by both, across the ranks' border, counted once)."""
    import os
    import shutil

    from conftest import FLOOR_STL, POUR_SCRIPT
    if shutil.which("mpirun") is None:
        pytest.fail("no mpirun: tools/setup.sh --engines installs it")
    local = lambda c: " ".join(f"c_{c}[{k}]" for k in range(1, 17))
    script = (POUR_SCRIPT.format(pair=local("cp"), wall=local("cw")).replace("post/pair.* ", "post/pair.*.% ")
              .replace("post/wall.* ", "post/wall.*.% "))
    script = "".join(ln + "\n" for ln in script.splitlines() if not ln.startswith(("dump d2", "dump d3", "dump dv",
                                                                                  "dump dl1", "dump dw1")))
    (tmp_path / "post").mkdir()
    (tmp_path / "in.pour").write_text(script)
    (tmp_path / "floor.stl").write_text(FLOOR_STL)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    done = subprocess.run(["mpirun", "--oversubscribe", "-np", "2", "liggghts", "-in", "in.pour", "-log",
                           "log.liggghts"], cwd=tmp_path, capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stdout[-2000:]
    bare = [p for p in (tmp_path / "post").glob("pair.*.1") if p.stat().st_size]
    assert bare and not bare[0].read_text().startswith("ITEM")          # rows without a header
    (tmp_path / "scene.toml").write_text(GLASS + STEEL_WALL)
    run = post(tmp_path / "post" / "dump.*", "--scene", tmp_path / "scene.toml", "--contacts",
               tmp_path / "post" / "pair.*", tmp_path / "post" / "wall.*", "--script", tmp_path / "in.pour",
               "--out", tmp_path / "out")
    assert run.returncode == 0, run.stderr

    def first_appearances(kind, key):
        steps = sorted({int(p.name.split(".")[1]) for p in (tmp_path / "post").glob(f"{kind}.*.0")})
        previous, count = set(), 0
        for step in steps:
            rows = (tmp_path / "post" / f"{kind}.{step}.0").read_text().splitlines()[9:]
            rows += (tmp_path / "post" / f"{kind}.{step}.1").read_text().splitlines()
            current = {key(r.split()) for r in rows if r.strip()}
            count += len(current - previous)
            previous = current
        return count
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    pairs = first_appearances("pair", lambda w: frozenset((w[12], w[13])))
    walls = first_appearances("wall", lambda w: (w[12], w[14]))
    print(summary["collisions"], pairs, walls)
    assert summary["complete"] is True and summary["particles"] == 60
    assert summary["collisions"] == {"particle_particle": pairs, "particle_wall": walls} and pairs > 50


def test_the_heat_path_is_the_runs_choice(tmp_path):
    """--heat-path exact evaluates the models by the exact path, as a run's effects.heat_path
    does (post used the tables only): the pair's heat agrees with the tables' to their stated
    accuracy (3.1e-9 at most, README's benchmark), and is not the tables' number itself."""
    hot_and_cold(tmp_path, hot_from=10)
    Q = {}
    for path in ("fast", "exact"):
        r = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--heat-path", path,
                 "--out", tmp_path / path)
        assert r.returncode == 0, r.stderr
        [row] = rows(tmp_path / path)
        Q[path] = np.array([float(row[f"Q_{m}"]) for m in "ABC"])
    assert np.all(Q["fast"] > 0)
    assert Q["exact"] == pytest.approx(Q["fast"], rel=1e-8)
    assert np.any(Q["exact"] != Q["fast"])
    bad = post(tmp_path / "run.dump", "--scene", tmp_path / "scene.toml", "--dt", "1e-6", "--heat-path", "table",
               "--out", tmp_path / "bad")
    assert bad.returncode == 2 and "--heat-path" in bad.stderr and "exact" in bad.stderr
