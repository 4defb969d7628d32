"""The coupling loop on the real LIGGGHTS: temperatures in LIGGGHTS' Temp, contacts from its
own lists, fix heat/gran and collision heat together counting no contact time twice."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from plugins.heat import Pair, collide
from plugins.heat.batch import pair_properties
from pyhost.scene import load_scene

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
TWO = (ROOT / "cases" / "two-particles" / "case.toml").read_text()
C = 4 / 3 * np.pi * 2e-3**3 * 7800 * 470          # m c of one sphere [J/K]


def run(case: Path, *extra):
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case.parent), "--out", str(case.parent / "out"),
                        *extra], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return r.stdout, json.loads((case.parent / "out" / "summary.json").read_text())


def test_isothermal_scene_adds_and_samples_nothing(tmp_path):
    case = tmp_path / "case.toml"
    case.write_text(TWO.replace('contact_heat = "A"', 'contact_heat = "none"')
                    .replace("restitution_feedback = true", "restitution_feedback = false"))
    out, summary = run(case)
    assert "host adds to the script: nothing" in out
    assert summary["collisions"] == 0 and "energy_balance_error" not in summary


REFERENCE = """
import json, sys
from pathlib import Path
from pyhost.engines.liggghts.worlds import box_world
from pyhost.engines.dem import Dem
from pyhost.scene import load_scene
from pyhost.engines.liggghts.script import Command, read_script
case = Path(sys.argv[1])
script, _ = box_world(load_scene(case), case.parent / "ref")
dem = Dem(case.parent / "ref" / "dem")
commands = read_script(script)
for cmd in commands[:-1]:
    dem.command(cmd)
dem.command(Command("compute collheat_ref all pair/gran/local id heatFlux", "(test)", 0))
dem.prepare(heat=False)
dem.atoms().T[:] = [400.0, 300.0]
flux = []
for step in range(int(commands[-1].words[1])):
    dem.run(1)
    rows = dem.lmp.local_array("collheat_ref")      # id_i, id_j, periodic, heatFlux into id_i [W]
    if len(rows) and rows[0, 0] > 0:
        flux.append(float(rows[0, 3]) * (1 if int(rows[0, 0]) == 2 else -1))
print(json.dumps([flux, float(dem.atoms().T[list(dem.atoms().id).index(2)])]))
"""


def heat_gran_flux(case: Path):
    """Reference: LIGGGHTS' heat/gran alone on the same collision, stepped one step at a
    time (in its own process, like every in-process engine of these tests): the heat flux
    [W] into the cold sphere at each step in contact, and its final temperature [K]."""
    r = subprocess.run([sys.executable, "-c", REFERENCE, str(case)], capture_output=True, text=True, cwd=ROOT,
                       timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    flux, T_cold = json.loads(r.stdout.strip().splitlines()[-1])
    return np.array(flux) * load_scene(case).time.dem_step, (T_cold - 300.0) * C


def test_long_contact_is_conducted_once(tmp_path):
    """The DEM's softened contact lasts ~230 us, the real collision 14 us. With heat/gran on,
    the cold sphere gets the plugin's Q for the first t_coll and heat/gran's heat after it.
    What heat/gran moved in the first t_coll is taken back from the recorder's per-step flux
    history: the reference's steps (the last one in part) to 2e-5 (measured 4.5e-6: the run's
    t_coll comes from the plugin's fast path, 1e-6, and sets the part)."""
    case = tmp_path / "case.toml"
    case.write_text(TWO.replace("enduring_conduction = false", "enduring_conduction = true")
                    .replace("restitution_feedback = true", "restitution_feedback = false")
                    .replace("[output]", "[output]\nvtk = false\npictures = false"))
    _, summary = run(case)
    steel = load_scene(case).materials["steel"]
    ref = collide(0.4, Pair(R1=2e-3, R2=2e-3, dT=100.0, **pair_properties(steel, steel)), "A")
    per_step, heat_gran_total = heat_gran_flux(case)
    dt = load_scene(case).time.dem_step
    n_coll = int(round(ref.t_coll / dt))
    expected = ref.Q + per_step[n_coll:].sum()
    rows = (case.parent / "out" / "history.csv").read_text().splitlines()
    header = rows[0].split(",")
    last = dict(zip(header, rows[-1].split(",")))
    gained = (float(last["T_group1"]) - 300.0) * C
    print(f"plugin Q {ref.Q:.4e} J, heat/gran alone {heat_gran_total:.4e} J ({len(per_step)} steps in contact, "
          f"{per_step[:n_coll].sum():.3e} J in the first t_coll), expected {expected:.4e} J, got {gained:.4e} J")
    assert heat_gran_total == pytest.approx(per_step.sum(), rel=1e-3)   # the flux sums to heat/gran's heat
    assert gained == pytest.approx(expected, rel=0.01)
    assert abs(summary["energy_balance_error"]) < 1e-12
    share = np.clip(ref.t_coll / dt - np.arange(len(per_step)), 0.0, 1.0)
    assert summary["heat_gran_undone"] == pytest.approx(abs(np.sum(per_step * share)), rel=2e-5)


class Recording:
    """The DEM, keeping the velocities by atom id after each run."""

    def __init__(self, dem):
        self.dem, self.v = dem, None

    def run(self, n):
        self.dem.run(n)
        a = self.dem.atoms(False)
        self.v = a.v[np.argsort(a.id)].copy()

    def __getattr__(self, name):
        return getattr(self.dem, name)


def restart_run(workdir, touching: bool) -> list:
    """A run started from given particles (a restart) of the two-spheres scene: collisions,
    heat moved [J], final velocities [m/s] (by id)."""
    import dataclasses

    from pyhost.world import simulate
    from pyhost.engines.liggghts.box_input import place_particles

    case = Path(workdir) / "case.toml"
    case.write_text(TWO)
    scene = load_scene(case)
    scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, end=1e-3))
    start = place_particles(scene)
    if touching:
        start = dataclasses.replace(start, position=start.position + [[0, 0, 0], [-2.1e-4, 0, 0]],
                                    velocity=0.0 * start.velocity)
    dem = {}
    summary = simulate(scene, Path(workdir) / "out", progress_every=1e9, start=start,
                       wrap=lambda d: dem.setdefault("d", Recording(d)))
    return [summary["collisions"], summary["heat_moved"], dem["d"].v.tolist()]


@pytest.mark.parametrize("touching", [False, True])
def test_contacts_present_at_a_restart_are_not_collisions(tmp_path, touching):
    """Two spheres already in contact (10 um overlap, at rest) at a restart are a contact that
    was there, not a collision; the same spheres apart and closing in at 0.4 m/s collide as in
    the scene. Run in a fresh process, like every engine of these tests."""
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); import test_coupling as t; "
            "print(json.dumps(t.restart_run(sys.argv[2], sys.argv[3] == '1')))")
    r = subprocess.run([sys.executable, "-c", code, str(Path(__file__).parent), str(tmp_path),
                        "1" if touching else "0"], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    collisions, heat_moved, v = json.loads(r.stdout.strip().splitlines()[-1])
    v = np.array(v)
    assert collisions == (0 if touching else 1)
    assert (heat_moved == 0.0) if touching else (heat_moved > 0)
    assert np.isfinite(v).all() and v[0, 0] < 0 < v[1, 0]      # apart again (with restitution feedback on)
