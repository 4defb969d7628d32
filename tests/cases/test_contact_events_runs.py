"""Collisions from contact events recorded inside LIGGGHTS, on the small cases run for real:
against closed forms (a head-on pair, a drop onto a plane) and against LIGGGHTS' own contact
list read at every step. Restitution feedback is off unless a test says otherwise.

Until session 33 a run could also sample the contact lists every few steps (``[time] contacts
= "samples"``), and these tests compared the two; the figures of that comparison are in
docs/contact-events.md."""
import csv
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from plugins.heat import Pair, collide
from plugins.heat.batch import pair_properties
from pyhost.scene import load_scene

pytestmark = pytest.mark.engines
CASES = Path(__file__).resolve().parents[2] / "cases"


def run(case, tmp_path, *extra, restitution=False):
    folder = tmp_path / case
    shutil.copytree(CASES / case, folder)
    text = (folder / "case.toml").read_text()
    if not restitution:
        text = text.replace("restitution_feedback = true", "restitution_feedback = false")
    (folder / "case.toml").write_text(text)
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out"), *extra],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    added = next(ln for ln in r.stdout.splitlines() if ln.startswith("host adds to the script"))
    assert "collheat_events" in added, added
    rows = list(csv.DictReader(open(folder / "out" / "collisions.csv")))
    return rows, json.loads((folder / "out" / "summary.json").read_text())


def test_two_particles_from_events_have_the_exact_impact_speed(tmp_path):
    """0.2 m/s each, head on, no gravity: one collision, its impact speed 0.4 m/s to
    round-off (nothing integrated back), its heat the plugin's at 0.4 m/s to 1e-12."""
    rows, summary = run("two-particles", tmp_path)
    assert summary["collisions"] == 1
    assert float(rows[0]["v0"]) == pytest.approx(0.4, rel=1e-12)
    steel = load_scene(CASES / "two-particles" / "case.toml").materials["steel"]
    ref = collide(0.4, Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel)), "A")
    assert abs(float(rows[0]["Q"])) == pytest.approx(ref.Q, rel=1e-12)
    assert summary["heat_moved"] == pytest.approx(ref.Q, rel=1e-12)
    assert abs(summary["energy_balance_error"]) < 1e-12


def test_wall_impact_from_events(tmp_path):
    """1 m/s onto a primitive floor: one wall collision at exactly 1 m/s."""
    rows, summary = run("wall-impact", tmp_path)
    assert summary["particle_wall"] == 1 and summary["particle_particle"] == 0
    assert float(rows[0]["v0"]) == pytest.approx(1.0, rel=1e-12)
    assert abs(summary["heat_from_walls"]) > 0 and abs(summary["energy_balance_error"]) < 1e-12


# hot-cold-box's generated script stepped one step at a time through the bridge (each step
# continues the last without a set-up, as the host's chunks do), LIGGGHTS' own pair list read
# after each: the contacts that begin at each step, and their approach speed at the recorder's
# moment (post_force, before the step's final half kick).
CONTACT_LIST = """
import dataclasses, json, sys
from pathlib import Path
import numpy as np
from pyhost.engines.liggghts import Liggghts
from pyhost.scene import load_scene
from pyhost.engines.liggghts.script import read_script
from pyhost.engines.liggghts.worlds import box_world
case, out = Path(sys.argv[1]), Path(sys.argv[2])
scene = load_scene(case)
scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, end=scene.time.test_end))
script, _ = box_world(scene, out)
commands = read_script(script)
lmp = Liggghts(out / "dem")
for cmd in commands[:-1]:
    lmp.command(cmd.text)
lmp.command("compute collheat_ref all pair/gran/local pos vel id")
lmp.run(0)
dt = lmp.dt
lo, hi = np.array(scene.domain.box[0::2]), np.array(scene.domain.box[1::2])
def contacts():
    a = lmp.local_array("collheat_ref")      # x_i, x_j, v_i, v_j, id_i, id_j, periodic
    a = a[a[:, 12] > 0]
    d = a[:, 0:3] - a[:, 3:6]
    d -= (hi - lo) * np.round(d / (hi - lo))
    n = d / np.linalg.norm(d, axis=1)[:, None]
    i, j = a[:, 12].astype(int), a[:, 13].astype(int)
    # the relative velocity at the end of the step, less the half step of the forces it has had
    # since the recorder read it (final_integrate: v += dt/2 f/m); a periodic image (column 14)
    # keeps the velocity communicated before that
    at = {k: n for n, k in enumerate(lmp.atom("id").astype(int).tolist())}
    f, m = lmp.atom("f"), lmp.atom("rmass")
    ki, kj = (np.array([at[p] for p in ids.tolist()], int) for ids in (i, j))
    kick = 0.5 * dt * (f[ki] / m[ki, None] - (a[:, 14] == 0)[:, None] * f[kj] / m[kj, None])
    vn = -np.einsum("ij,ij->i", a[:, 6:9] - a[:, 9:12] - kick, n)
    return {(min(p, q), max(p, q)): v for p, q, v in zip(i.tolist(), j.tolist(), vn.tolist())}
last, begins = contacts(), []
for step in range(1, int(commands[-1].words[1]) + 1):
    lmp.run(1)
    now = contacts()
    begins += [[step, i, j, now[i, j]] for i, j in sorted(set(now) - set(last))]
    last = now
print(json.dumps(dict(begins=begins)))
"""


def test_hot_cold_box_collisions_are_liggghts_own_contacts_that_begin(tmp_path):
    """Two halves of a dense periodic box at 400 and 300 K for 10 ms (-test): the run's
    collision log lists, step for step, the pairs that appear in LIGGGHTS' own contact list
    (compute pair/gran/local read at every step of the same generated script), less those
    that begin without closing in (counted apart as contacts_without_impact); each at the
    approach speed of that list at its first step, less the half step of force the list's
    velocities have had since the recorder read them (measured: 8,218 collisions, speeds
    at most 2e-14 apart; asserted 1e-12). The log's heat sums to heat_moved, and the balance
    closes."""
    rows, summary = run("hot-cold-box", tmp_path, "--test")
    r = subprocess.run([sys.executable, "-c", CONTACT_LIST, str(tmp_path / "hot-cold-box" / "case.toml"), str(tmp_path / "ref")],
                       capture_output=True, text=True, timeout=600, cwd=Path(__file__).resolve().parents[2])
    assert r.returncode == 0, r.stderr[-3000:]
    ref = json.loads(r.stdout.strip().splitlines()[-1])["begins"]
    dt = load_scene(CASES / "hot-cold-box" / "case.toml").time.dem_step
    logged = {(round(float(row["time"]) / dt), int(row["i"]), int(row["j"])): float(row["v0"]) for row in rows}
    listed = {(s, i, j): v for s, i, j, v in ref}
    print(f"{len(logged)} collisions logged, {len(listed)} contacts begun in LIGGGHTS' list, "
          f"{summary.get('contacts_without_impact', 0)} without impact")
    assert len(logged) == len(rows) == summary["collisions"] > 1000
    assert set(logged) <= set(listed)
    assert len(listed) - len(logged) == summary.get("contacts_without_impact", 0)
    keys = sorted(logged)
    v_run, v_list = np.array([logged[k] for k in keys]), np.array([listed[k] for k in keys])
    rel = np.abs(v_list / v_run - 1)
    print(f"approach speed, LIGGGHTS' list against the recorder: median {np.median(rel):.2g}, max {rel.max():.2g}")
    assert rel.max() < 1e-12
    assert np.abs([float(row["Q"]) for row in rows]).sum() == pytest.approx(summary["heat_moved"], rel=1e-12)
    assert abs(summary["energy_balance_error"]) < 1e-12


def test_a_script_with_fix_heat_gran_runs_on_events(tmp_path):
    """cases/silo-heat --test (a user's script: fix heat/gran with area correction, insertion,
    an STL tube and a shaken plate): particle and wall collisions (the shaken plate's with the
    approach speed relative to the moving mesh: no contact without impact from the plate
    pushing resting particles), heat/gran's conduction during the collisions' model time taken
    back from the recorder's per-step flux (a small part of the collision heat: each t_coll is
    about one DEM step), and the energy balance closed to 1e-12 (inserted particles enter with
    their Temp at their first step). Against samples every 5 steps (session 32, measured):
    6,494 against 6,489 particle and 1,300 against 1,299 wall collisions, heat 0.34 % apart,
    3.1e-5 J taken back against 2.9e-4 J."""
    _, ev = run("silo-heat", tmp_path, "--test")
    print({k: ev.get(k) for k in ("particle_particle", "particle_wall", "heat_moved", "heat_gran_undone")})
    assert ev["particle_particle"] > 5000 and ev["particle_wall"] > 1000
    assert ev["contacts_without_impact"] == 0
    assert 0 < ev["heat_gran_undone"] < 0.1 * ev["heat_moved"]
    assert abs(ev["energy_balance_error"]) < 1e-12


def test_restitution_feedback_on_events_is_imposed_at_the_contact_end(tmp_path):
    """two-particles with restitution feedback (the model's e imposed when the contact ends):
    the recorder imposes e v0 on the pair's normal velocity at the step the contact ends, so
    the spheres fly apart at the model's e times 0.4 m/s to 1e-12 (nothing acts on them after),
    none imposed late."""
    import meshio

    rows, summary = run("two-particles", tmp_path, restitution=True)
    assert summary["collisions"] == 1
    assert summary["restitution_late"] == summary["restitution_not_imposed"] == 0
    e, v0 = float(rows[0]["e"]), float(rows[0]["v0"])
    assert 0 < e < 1 and v0 == pytest.approx(0.4, rel=1e-12)
    last = sorted((tmp_path / "two-particles" / "out" / "vtk").glob("particles_*.vtu"))[-1]
    v = meshio.read(last).point_data["velocity"]
    assert v[1, 0] - v[0, 0] == pytest.approx(e * v0, rel=1e-12)


def test_a_scene_asking_for_samples_is_told_they_are_retired(tmp_path):
    """``[time] contacts = "samples"`` (a scene of an earlier version): a SceneError naming the
    key and saying why, exit 2, nothing run."""
    folder = tmp_path / "case"
    shutil.copytree(CASES / "two-particles", folder)
    toml = folder / "case.toml"
    toml.write_text(re.sub(r"^\[time\]$", '[time]\ncontacts = "samples"', toml.read_text(), count=1, flags=re.M))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out")],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 2 and "time.contacts: retired" in r.stderr
    assert not (folder / "out" / "collisions.csv").exists()
