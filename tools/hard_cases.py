"""Hard cases: the contact plugin at extreme speeds, sizes and moduli, and coupled box scenes
near the DEM's stability limit. Each either runs finite (and, coupled, conserves sum(m c T)
to 1e-12) or is refused up front with its reason; nothing ends in NaN or a traceback.

    python tools/hard_cases.py            # prints the table of docs/hard-cases.md (about a minute)

tests/unit/test_hard_case_suite.py and tests/cases/test_hard_box_scenes.py check the same
lists case by case.
"""
from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

SPEEDS = (1e-3, 0.1, 1.0, 10.0, 30.0, 100.0, 1e3, 1e6, 1e300)      # m/s
PAIRS = {   # name: collide options (paper set otherwise: steel-like, R = 2 mm)
    "paper": [],
    "wall": ["--wall"],
    "tiny R = 1 um": ["--R1", "1e-6", "--R2", "1e-6"],
    "huge R = 1 m": ["--R1", "1", "--R2", "1"],
    "size ratio 1e4": ["--R1", "1e-6", "--R2", "1e-2"],
    "stiff E* = 1e12 Pa, Y = 1e10 Pa": ["--Estar", "1e12", "--Y", "1e10"],
    "soft E* = 1e6 Pa, Y = 1e5 Pa": ["--Estar", "1e6", "--Y", "1e5"],
    "heavy rho = 2e4": ["--rho1", "2e4", "--rho2", "2e4"],
    "light rho = 10": ["--rho1", "10", "--rho2", "10"],
    "R = 1e100 m": ["--R1", "1e100", "--R2", "1e100"],
    "E* = 1e300 Pa": ["--Estar", "1e300"],
    "dT = 1e308 K": ["--dT", "1e308"],
}
PLUGIN_CASES = [(pair, v0) for pair in PAIRS for v0 in SPEEDS]


def plugin_case(pair: str, v0: float) -> dict:
    """``python -m pyhost collide --model all --json`` for one pair and speed, in process:
    exit code, the rows (models A, B, C) or the one-line refusal."""
    from pyhost.cli import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["collide", "--json", "--model", "all", "--v0", repr(v0), *PAIRS[pair]])
    rows = json.loads(out.getvalue()) if code == 0 else []
    return dict(code=code, rows=rows, error=err.getvalue().strip().splitlines()[-1] if code else "")


def hot_cold_box(**changes) -> dict:
    """cases/hot-cold-box, 200 particles for 4 ms, with ``changes`` (dotted keys)."""
    scene = tomllib.loads((ROOT / "cases" / "hot-cold-box" / "case.toml").read_text())
    for g, z in zip(scene["particles"], ([0.0, 0.02], [0.02, 0.04])):
        g.update(count=100, region=[0.0, 0.02, 0.0, 0.02, *z])
    scene["time"].update(end=4e-3, test_end=0.0)
    scene["output"] = dict(every=1e-3, vtk=False, pictures=False)
    for key, value in changes.items():
        *head, last = key.split(".")
        node = scene
        for k in head:
            node = node[int(k)] if k.isdigit() else node[k]
        node[last] = value
    return scene


def both_groups(key, value) -> dict:
    return {f"particles.0.{key}": value, f"particles.1.{key}": value}


BOX_CASES = {   # name: scene
    "spread 1 m/s (base)": hot_cold_box(),
    "spread 10 m/s": hot_cold_box(**both_groups("velocity_spread", 10.0)),
    "spread 30 m/s, 17 steps per collision": hot_cold_box(**both_groups("velocity_spread", 30.0), **{"time.dem_step": 2e-6}),
    "spread 100 m/s, 13 steps per collision": hot_cold_box(**both_groups("velocity_spread", 100.0), **{"time.dem_step": 2e-6}),
    "spread 100 m/s, 9 steps per collision": hot_cold_box(**both_groups("velocity_spread", 100.0), **{"time.dem_step": 3e-6}),
    "dense start, 1000 beads": hot_cold_box(**both_groups("count", 500)),
    "stiff real modulus 210 GPa in the DEM": hot_cold_box(**{"materials.steel.dem.youngs_modulus": 210e9,
                                                            "time.dem_step": 2e-7}),
    "stiff 210 GPa, step of the soft DEM": hot_cold_box(**{"materials.steel.dem.youngs_modulus": 210e9}),
    "tiny beads R = 50 um": hot_cold_box(**both_groups("radius", 50e-6), **{"time.dem_step": 1e-7,
                                         "domain.box": [0.0, 0.002, 0.0, 0.002, 0.0, 0.004],
                                         "particles.0.region": [0.0, 0.002, 0.0, 0.002, 0.0, 0.002],
                                         "particles.1.region": [0.0, 0.002, 0.0, 0.002, 0.002, 0.004]}),
    "model B with restitution feedback, spread 30 m/s": hot_cold_box(
        **both_groups("velocity_spread", 30.0), **{"time.dem_step": 2e-6, "effects.contact_heat": "B",
                                                   "effects.restitution_feedback": True}),
    "model C, exact path, spread 10 m/s": hot_cold_box(
        **both_groups("velocity_spread", 10.0), **{"effects.contact_heat": "C", "effects.heat_path": "exact"}),
    "walls at 1500 K and 100 K, enduring conduction, spread 10 m/s": hot_cold_box(
        **both_groups("velocity_spread", 10.0), **{"effects.enduring_conduction": True,
                                                   "domain.periodic": [True, True, False],
                                                   "walls": [dict(plane="zlo", material="steel", temperature=1500.0),
                                                             dict(plane="zhi", material="steel", temperature=100.0)]}),
}


def box_case(name: str, folder: Path) -> dict:
    """Run one box scene with ``python -m pyhost run``: exit code, summary and last message."""
    import tomli_w
    case = folder / "case"
    case.mkdir(parents=True, exist_ok=True)
    (case / "case.toml").write_text(tomli_w.dumps(BOX_CASES[name]))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--out", str(folder / "out")],
                       capture_output=True, text=True, cwd=ROOT)
    summary = folder / "out" / "summary.json"
    return dict(code=r.returncode, error=(r.stderr.strip().splitlines() or [""])[-1] if r.returncode else "",
                summary=json.loads(summary.read_text()) if summary.exists() else None)


def main() -> None:
    print("| pair | v0 [m/s] | exit | outcome |\n|---|---:|---:|---|")
    for pair, v0 in PLUGIN_CASES:
        r = plugin_case(pair, v0)
        flags = sorted({f for row in r["rows"] for f in row["flags"]})
        what = r["error"].removeprefix("error: ")[:90] if r["code"] else ("finite; flags: " + ", ".join(flags)
                                                                           if flags else "finite")
        print(f"| {pair} | {v0:g} | {r['code']} | {what} |")
    print("\n| box scene | exit | outcome |\n|---|---:|---|")
    for name in BOX_CASES:
        with tempfile.TemporaryDirectory() as d:
            r = box_case(name, Path(d))
        s = r["summary"]
        what = (f"{s['collisions']} collisions, sum(m c T) error {s['energy_balance_error']:.1e}"
                if r["code"] == 0 else "refused: case.toml: " + r["error"].split("case.toml: ", 1)[-1])
        print(f"| {name} | {r['code']} | {what} |")


if __name__ == "__main__":
    main()
