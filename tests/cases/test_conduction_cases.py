"""Lasting conduction on the real LIGGGHTS: MFiX's two DEM heat verification problems
(cases/two-sphere-conduction, cases/pfp-conduction) against their analytic curves, and a
collision's contact conducting only after the collision's model time t_coll."""
import csv
import json
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"


def run(case: Path, out: Path) -> tuple[dict, float]:
    start = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(out)],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    seconds = time.perf_counter() - start
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return json.loads((out / "summary.json").read_text()), seconds


def analytic(t, A, B, T1=298.15, T2=453.15):
    """MFiX's analytic temperatures of the cold and the hot particle (usr2_des.f of both
    problems): A = H/(m1 c1), B = H/(m2 c2) [1/s]."""
    e = np.exp(-(A + B) * t)
    return ((B * T1 + A * T2 + A * (T1 - T2) * e) / (A + B), (B * T1 + A * T2 - B * (T1 - T2) * e) / (A + B))


def curves(out: Path):
    rows = list(csv.DictReader(open(out / "history.csv")))
    return tuple(np.array([float(r[k]) for r in rows]) for k in ("time", "T_group0", "T_group1"))


@pytest.mark.parametrize("case, rates, end, tolerance", [
    ("two-sphere-conduction", (0.01027998273952850, 0.00410668176759131), 500.0, 0.01),
    ("pfp-conduction", (0.0401067383450698, 0.0160219735083726), 300.0, 0.05),
])
def test_mfix_verification_problem(tmp_path, case, rates, end, tolerance):
    """Each particle's temperature, every simulated second, within the tolerance [K] of the
    analytic curve of MFiX's problem up to its end; the balance closes to 1e-12; under 30 s.
    Measured: contact 7e-13 K (the pair exchange is exact at any interval, and mfix gives the
    published rates to 1e-12); pfp 2.8e-3 K (cold) and 1.1e-3 K (hot), the published rates
    being 6.9e-5 below MFiX's own formula."""
    summary, seconds = run(CASES / case, tmp_path / "out")
    t, cold, hot = curves(tmp_path / "out")
    want_cold, want_hot = analytic(t, *rates)
    err = max(np.abs(cold - want_cold).max(), np.abs(hot - want_hot).max())
    print(f"{case}: {len(t)} rows to {t[-1]:g} s, max |T - analytic| cold {np.abs(cold - want_cold).max():.3g} K, "
          f"hot {np.abs(hot - want_hot).max():.3g} K; balance {summary['energy_balance_error']:.2g}; {seconds:.1f} s")
    assert t[-1] == pytest.approx(end, rel=1e-12) and len(t) == end + 1
    assert err < tolerance
    assert abs(summary["energy_balance_error"]) < 1e-12
    assert summary["heat_conducted_contact" if case.startswith("two") else "heat_conducted_gap"] > 0
    assert seconds < 30


def scene(tmp_path: Path, name: str, contact_heat: str, end: float | None = None) -> Path:
    """cases/two-particles (two steel spheres meeting head-on at 0.4 m/s, 400 K and 300 K) with
    lasting contact conduction updated every step."""
    text = (CASES / "two-particles" / "case.toml").read_text()
    text = text.replace('contact_heat = "A"', f'contact_heat = "{contact_heat}"\ncontact_conduction = "mfix"')
    text = text.replace("restitution_feedback = true", "restitution_feedback = false")
    if end is not None:
        text = text.replace("end = 2e-3", f"end = {end!r}").replace("test_end = 1.5e-3", "")
    text = text.replace("[output]\n", "[output]\nvtk = false\npictures = false\n")
    text += "\n[conduction]\nevery = 1\n"
    folder = tmp_path / name
    folder.mkdir()
    (folder / "case.toml").write_text(text)
    assert tomllib.loads(text)["effects"]["contact_conduction"] == "mfix"
    return folder


def test_a_collision_owns_its_contact_for_t_coll(tmp_path):
    """Two spheres meet and stay in the DEM's soft contact about 230 us; model A's collision
    lasts t_coll = 14.2 us. A run that ends halfway through t_coll conducts nothing through the
    contact when the collision heat is on (its heat stands for that time), and conducts without
    it; the whole run conducts through the contact after t_coll. Balance to 1e-12 in each."""
    whole, _ = run(scene(tmp_path, "whole", "A"), tmp_path / "whole" / "out")
    rows = list(csv.DictReader(open(tmp_path / "whole" / "out" / "collisions.csv")))
    assert len(rows) == 1
    t_b, t_coll = float(rows[0]["time"]), float(rows[0]["t_coll"])
    half = t_b + 0.5 * t_coll
    owned, _ = run(scene(tmp_path, "owned", "A", half), tmp_path / "owned" / "out")
    alone, _ = run(scene(tmp_path, "alone", "none", half), tmp_path / "alone" / "out")
    print(f"collision at {t_b:.6g} s, t_coll {t_coll:.4g} s; conducted through the contact: whole run "
          f"{whole['heat_conducted_contact']:.4g} J, to t_coll/2 with collision heat "
          f"{owned['heat_conducted_contact']:.4g} J, without {alone['heat_conducted_contact']:.4g} J")
    assert owned["collisions"] == 1 and owned["heat_conducted_contact"] == 0.0
    assert alone["heat_conducted_contact"] > 0.0
    assert whole["heat_conducted_contact"] > 0.0
    for s in (whole, owned, alone):
        assert abs(s["energy_balance_error"]) < 1e-12


@pytest.mark.long
def test_conduction_stopped_within_t_coll_restarts_bit_for_bit(tmp_path):
    """The collision-and-contact run above stopped by SIGTERM at step 2540, inside the
    collision's t_coll (it began at step 2501 and owns its contact to step 2572), and restarted
    from the checkpoint: collisions.csv, history.csv and summary.json (heat_conducted_contact
    included) equal to the last bit those of the run that wrote a periodic checkpoint there and
    went on. The checkpoint keeps when the last update was and which contacts a collision owns."""
    from test_user_scripts import restarts_bit_for_bit

    case = scene(tmp_path, "case", "A")
    whole = restarts_bit_for_bit(case, ("test_end = 1.5e-3", "test_end = 1.5e-3"), 2540 * 2e-7,
                                 "checkpoint at t = 0.000508 s (step 2540)", 2540)
    assert whole["heat_conducted_contact"] > 0.0 and whole["collisions"] == 1


def test_a_pair_across_a_periodic_side_conducts_as_in_the_open(tmp_path):
    """The pfp problem with x periodic and the box 10 mm long, the spheres placed so that they
    face each other across the periodic side (6.52 mm apart inside the box, 3.48 mm through the
    side): the same temperatures as the open case, to 1e-9 K, over its smoke run (30 s)."""
    import shutil

    folders = {}
    for name, change in (("open", None), ("periodic", True)):
        folder = tmp_path / name
        shutil.copytree(CASES / "pfp-conduction", folder, ignore=shutil.ignore_patterns("output", "log.*"))
        if change:
            script = folder / "in.liggghts"
            text = script.read_text().replace("boundary f f f", "boundary p f f")
            text = text.replace("region box block 0 0.02", "region box block 0 0.01")
            text = text.replace("create_atoms 1 single 0.0115 ", "create_atoms 1 single 0.008 ")
            text = text.replace("create_atoms 2 single 0.01498 ", "create_atoms 2 single 0.00148 ")
            script.write_text(text)
        r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out"), "--test"],
                           capture_output=True, text=True, cwd=ROOT, timeout=300)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        folders[name] = curves(folder / "out")
    (t, cold, hot), (t_p, cold_p, hot_p) = folders["open"], folders["periodic"]
    assert np.array_equal(t, t_p) and t[-1] == pytest.approx(30.0)
    assert np.abs(cold - cold_p).max() < 1e-9 and np.abs(hot - hot_p).max() < 1e-9
    assert cold[-1] - cold[0] > 1.0


def test_contact_conduction_beside_a_scripts_heat_gran_is_refused(tmp_path):
    """A script whose fix heat/gran conducts through the particles' contacts, with
    contact_conduction asked for too: both would conduct through the same contacts. Exit 2,
    naming the key, the fix and the file, before any step."""
    import shutil

    folder = tmp_path / "both"
    shutil.copytree(CASES / "two-sphere-conduction", folder, ignore=shutil.ignore_patterns("output", "log.*"))
    script = folder / "in.liggghts"
    script.write_text(script.read_text().replace("timestep 0.1", (
        "fix m5 all property/global thermalConductivity peratomtype 55.03674204 0.84070944\n"
        "fix m6 all property/global thermalCapacity peratomtype 800.5329072 55.035486\n"
        "fix heat all heat/gran initial_temperature 300\ntimestep 0.1")))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out")],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert (f"{folder / 'case.toml'}: effects.contact_conduction = 'mfix': the script's fix heat/gran 'heat' "
            "conducts through the same contacts") in r.stderr


def test_a_granular_gas_with_both_paths_keeps_its_balance_and_range(tmp_path):
    """hot-cold-box (1000 steel spheres, periodic, hot and cold halves, model A) for 5 ms with
    morris contact conduction and rong_horio gas gaps (air, 0.026 W/(m K)) updated every 10
    steps: many particles with several partners at once. Energy balance to 1e-12, every
    temperature within the starting range, heat through both paths."""
    text = (CASES / "hot-cold-box" / "case.toml").read_text()
    text = text.replace('contact_heat = "A"', 'contact_heat = "A"\ncontact_conduction = "morris"\n'
                        'gap_conduction = "rong_horio"', 1)
    text = text.replace("test_end = 0.01", "test_end = 0.005")
    text = text.replace("[output]\n", "[output]\nvtk = false\npictures = false\n")
    folder = tmp_path / "box"
    folder.mkdir()
    (folder / "case.toml").write_text(text + "\n[conduction]\nevery = 10\ngas_conductivity = 0.026\n")
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(folder), "--out", str(folder / "out"), "--test"],
                       capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    s = json.loads((folder / "out" / "summary.json").read_text())
    rows = list(csv.DictReader(open(folder / "out" / "history.csv")))
    lo, hi = float(rows[0]["T_min"]), float(rows[0]["T_max"])
    print(f"{s['collisions']} collisions, {s['heat_moved']:.4g} J by collisions, {s['heat_conducted_contact']:.4g} J "
          f"through contacts, {s['heat_conducted_gap']:.4g} J through gas gaps; balance {s['energy_balance_error']:.2g}")
    assert abs(s["energy_balance_error"]) < 1e-12
    assert all(lo <= float(row["T_min"]) and float(row["T_max"]) <= hi for row in rows)
    assert s["heat_conducted_contact"] > 0 and s["heat_conducted_gap"] > 0 and s["collisions"] > 1000
