"""The batch delay of contact events (docs/contact-events.md, "The batch delay"): a collision's
heat is moved at the next harvest, up to HARVEST_EVERY = 1,000 DEM steps after its own step,
not at that step. Each test runs a case twice in this process, harvesting at most every
1,000 steps (the default) and at (nearly) every step, and compares."""
import csv
import dataclasses
from pathlib import Path

import pytest

from pyhost.effects import collisions as collision_effect
from pyhost.scene import load_scene
from pyhost.world import simulate

pytestmark = pytest.mark.engines
CASES = Path(__file__).resolve().parents[2] / "cases"


def run(case: str, out, harvest_every: int, monkeypatch, **time):
    monkeypatch.setattr(collision_effect, "HARVEST_EVERY", harvest_every)
    scene = load_scene(CASES / case / "case.toml")
    scene = dataclasses.replace(scene, time=dataclasses.replace(scene.time, **time),
                                output=dataclasses.replace(scene.output, vtk=False, pictures=False))
    summary = simulate(scene, out, test=scene.scripted, progress_every=1e9)
    return summary, list(csv.DictReader(open(out / "collisions.csv"))), list(csv.DictReader(open(out / "history.csv")))


@pytest.mark.long
def test_without_heat_gran_the_delay_changes_nothing(tmp_path, monkeypatch):
    """hot-cold-box, 10 ms (a dense granular gas, no fix heat/gran, no convection): nothing but
    the host changes a temperature between two harvests, and the host moves a batch's heat
    collision by collision in the order they happened, so harvesting every 1,000 steps gives,
    to the bit, the collisions (each one's heat) and the temperatures of harvesting at every
    step. Only the total heat moved, summed batch by batch, differs in its last digits."""
    end = load_scene(CASES / "hot-cold-box" / "case.toml").time.test_end
    batched, rows_b, hist_b = run("hot-cold-box", tmp_path / "batched", 1000, monkeypatch, end=end)
    stepwise, rows_s, hist_s = run("hot-cold-box", tmp_path / "stepwise", 1, monkeypatch, end=end)
    assert batched["collisions"] == stepwise["collisions"] > 1000
    assert rows_b == rows_s and hist_b == hist_s
    assert batched["heat_moved"] == pytest.approx(stepwise["heat_moved"], rel=1e-12)


def test_with_heat_gran_the_delay_stays_far_below_the_conduction_time(tmp_path, monkeypatch):
    """cases/silo-heat -test (a user's pour under fix heat/gran, 16,000 steps of 5 us):
    heat/gran changes temperatures at every step, so a collision's heat reaching Temp up to
    1,000 steps (5 ms) late is conducted on to the neighbours that much later. The scene's
    thermal time scale is that of heat/gran between touching particles, tau = m c / h with
    h = 4 k_i k_j / (k_i + k_j) sqrt(A): for its 2 mm glass beads (m c = 8.8e-3 J/K, k = 1
    W/(m K), a contact radius of about 0.1 mm) tau is about 25 s, 5,000 times the delay. The
    collision heat changes a bead's temperature by about 2.5e-4 K over the run (2e-3 J over 900
    beads), so the delay can shift temperatures by about that times 5 ms / tau, 5e-8 K.
    Against harvesting every 5 steps (25 us): the same collisions; group mean temperatures
    within 1e-7 K (measured 5e-9 K), heat moved within 1e-5 (measured 1.5e-8), heat/gran's
    conduction taken back within 1e-3 (measured 2.8e-5: heat/gran's flux during a collision's
    model time follows the temperatures, which the delayed heat of earlier collisions moves)."""
    batched, rows_b, hist_b = run("silo-heat", tmp_path / "batched", 1000, monkeypatch)
    fine, rows_f, hist_f = run("silo-heat", tmp_path / "fine", 5, monkeypatch)
    key = lambda r: (r["time"], r["i"], r["j"], r["wall"])
    assert sorted(map(key, rows_b)) == sorted(map(key, rows_f)) and len(rows_b) > 5000
    rel = lambda a, b: abs(a / b - 1)
    groups = [k for k in hist_b[0] if k.startswith("T_group")]
    dT = max(abs(float(hist_b[-1][k]) - float(hist_f[-1][k])) for k in groups)
    print(f"heat moved {rel(batched['heat_moved'], fine['heat_moved']):.2g} apart, heat/gran taken back "
          f"{rel(batched['heat_gran_undone'], fine['heat_gran_undone']):.2g}, group temperatures {dT:.2g} K")
    assert rel(batched["heat_moved"], fine["heat_moved"]) < 1e-5
    assert rel(batched["heat_gran_undone"], fine["heat_gran_undone"]) < 1e-3
    assert dT < 1e-7
    assert abs(batched["energy_balance_error"]) < 1e-12 and abs(fine["energy_balance_error"]) < 1e-12
