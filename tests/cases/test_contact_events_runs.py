"""Collisions from contact events recorded inside LIGGGHTS ([time] contacts = "events", the
default where it applies) against the sampled contact lists ("samples"), on the small cases
run for real. Restitution feedback is off unless a test says otherwise."""
import csv
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from plugins.heat import Pair, collide
from plugins.heat.batch import pair_properties
from pyhost.scene import load_scene

pytestmark = pytest.mark.engines
CASES = Path(__file__).resolve().parents[2] / "cases"


def run(case, tmp_path, mode, *extra, restitution=False):
    folder = tmp_path / f"{case}-{mode}"
    shutil.copytree(CASES / case, folder)
    text = (folder / "case.toml").read_text()
    if not restitution:
        text = text.replace("restitution_feedback = true", "restitution_feedback = false")
    (folder / "case.toml").write_text(re.sub(r"^\[time\]$", f'[time]\ncontacts = "{mode}"', text, count=1,
                                             flags=re.M))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out"), *extra],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    added = next(ln for ln in r.stdout.splitlines() if ln.startswith("host adds to the script"))
    assert ("collheat_events" in added) == (mode == "events"), added
    rows = list(csv.DictReader(open(folder / "out" / "collisions.csv")))
    return rows, json.loads((folder / "out" / "summary.json").read_text())


def test_two_particles_from_events_have_the_exact_impact_speed(tmp_path):
    """0.2 m/s each, head on, no gravity: the event's impact speed is 0.4 m/s to round-off;
    the sampled one, integrated back through the DEM's law, is 1.5e-5 off. The heat follows
    the plugin's at 0.4 m/s to 1e-12."""
    ev_rows, ev = run("two-particles", tmp_path, "events")
    sa_rows, sa = run("two-particles", tmp_path, "samples")
    assert ev["collisions"] == sa["collisions"] == 1
    assert float(ev_rows[0]["v0"]) == pytest.approx(0.4, rel=1e-12)
    assert float(sa_rows[0]["v0"]) == pytest.approx(0.4, rel=1e-4)
    steel = load_scene(CASES / "two-particles" / "case.toml").materials["steel"]
    ref = collide(0.4, Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel)), "A")
    assert abs(float(ev_rows[0]["Q"])) == pytest.approx(ref.Q, rel=1e-12)
    assert ev["heat_moved"] == pytest.approx(sa["heat_moved"], rel=1e-4)
    assert abs(ev["energy_balance_error"]) < 1e-12


def test_wall_impact_from_events(tmp_path):
    """1 m/s onto a primitive floor: one wall collision at exactly 1 m/s, its heat the
    sampled run's to 1e-4 (their impact speeds differ by the back-integration's 7e-6)."""
    ev_rows, ev = run("wall-impact", tmp_path, "events")
    _, sa = run("wall-impact", tmp_path, "samples")
    assert ev["particle_wall"] == sa["particle_wall"] == 1 and ev["particle_particle"] == 0
    assert float(ev_rows[0]["v0"]) == pytest.approx(1.0, rel=1e-12)
    assert ev["heat_from_walls"] == pytest.approx(sa["heat_from_walls"], rel=1e-4)


def test_hot_cold_box_from_events_agrees_with_samples(tmp_path):
    """Two halves of a dense box at 400 and 300 K for 10 ms (-test). Sampling every 10 steps
    misses a few short contacts that the events catch (counts within 0.1 %); the total heat
    agrees to 0.5 %: the events' impact speeds are those at first touch, the samples' are
    integrated back over up to 10 steps with a two-body law (a median 6e-4 apart, far more
    where a particle touches several others at once)."""
    _, ev = run("hot-cold-box", tmp_path, "events", "--test")
    _, sa = run("hot-cold-box", tmp_path, "samples", "--test")
    print(f"collisions {ev['collisions']} (events) {sa['collisions']} (samples); heat {ev['heat_moved']:.6e} "
          f"{sa['heat_moved']:.6e}")
    assert ev["collisions"] >= sa["collisions"] > 1000
    assert ev["collisions"] == pytest.approx(sa["collisions"], rel=1e-3)
    assert ev["heat_moved"] == pytest.approx(sa["heat_moved"], rel=5e-3)
    assert abs(ev["energy_balance_error"]) < 1e-12


def test_a_script_with_fix_heat_gran_runs_on_events(tmp_path):
    """cases/silo-heat --test (a user's script: fix heat/gran with area correction, insertion,
    an STL tube and a shaken plate) on events against samples every 5 steps: the same
    particle-particle collisions to 0.5 % (events also catch contacts shorter than 5 steps)
    and heat moved to 1 %; heat/gran's conduction during the collisions' model time taken back
    from the recorder's per-step flux, which is less than the samples take back (at least one
    whole sample interval per collision, however short t_coll); the energy balance closed to
    1e-12 (inserted particles enter with their Temp at their first step); the wall collisions,
    the shaken plate's included (the approach speed relative to the moving mesh), to 1 %.
    Measured: 6,494 against 6,489 particle and 1,300 against 1,299 wall collisions, heat 0.34 %
    apart, 3.1e-5 J taken back against 2.9e-4 J."""
    pick = tmp_path / "silo"
    _, ev = run("silo-heat", pick, "events", "--test")
    _, sa = run("silo-heat", pick, "samples", "--test")
    print({k: (ev.get(k), sa.get(k)) for k in ("particle_particle", "heat_moved", "heat_gran_undone")})
    assert ev["particle_particle"] == pytest.approx(sa["particle_particle"], rel=5e-3)
    assert ev["particle_wall"] == pytest.approx(sa["particle_wall"], rel=1e-2)
    assert "contacts_without_impact" not in ev
    assert ev["heat_moved"] == pytest.approx(sa["heat_moved"], rel=1e-2)
    assert 0 < ev["heat_gran_undone"] < sa["heat_gran_undone"]
    assert abs(ev["energy_balance_error"]) < 1e-12


def test_restitution_feedback_on_events_is_imposed_at_the_contact_end(tmp_path):
    """two-particles with restitution feedback (the model's e imposed when the contact ends):
    the recorder imposes e v0 on the pair's normal velocity at the step the contact ends, so
    the spheres fly apart at the model's e times 0.4 m/s to 1e-12 (nothing acts on them after),
    none imposed late; the samples' run, which imposes it at the first sample after the end,
    the same to 1e-9 (its v0 comes from the back-integration, 1.5e-5 off)."""
    import meshio

    def rebound(folder):
        last = sorted((folder / "out" / "vtk").glob("particles_*.vtu"))[-1]
        v = meshio.read(last).point_data["velocity"]
        return v[1, 0] - v[0, 0]

    ev_rows, ev = run("two-particles", tmp_path, "events", restitution=True)
    sa_rows, sa = run("two-particles", tmp_path, "samples", restitution=True)
    assert ev["collisions"] == sa["collisions"] == 1
    assert "restitution_late" not in ev and "restitution_not_imposed" not in ev
    e, v0 = float(ev_rows[0]["e"]), float(ev_rows[0]["v0"])
    assert 0 < e < 1 and v0 == pytest.approx(0.4, rel=1e-12)
    assert rebound(tmp_path / "two-particles-events") == pytest.approx(e * v0, rel=1e-12)
    e_s, v0_s = float(sa_rows[0]["e"]), float(sa_rows[0]["v0"])
    assert rebound(tmp_path / "two-particles-samples") == pytest.approx(e_s * v0_s, rel=1e-9)
