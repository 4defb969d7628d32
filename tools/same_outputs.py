"""Behaviour unchanged? Runs the box cases (``pyhost run CASE --test``; two of them also under
``mpirun -np 2``) and a few ``pyhost post``
jobs on the dumps of a real LIGGGHTS pour, and compares every output file byte for byte with
references saved before a change (issue 45).

    .venv/bin/python tools/same_outputs.py --save     # before the change: the references
    .venv/bin/python tools/same_outputs.py            # after it: exit 1 on any difference

What is left out of the comparison, because it is wall-clock time or says where the run was:
- summary.json: the keys ``elapsed_s``, ``wall_time_s``, ``wall_s``, ``seconds``, ``started``,
  ``finished``, ``host``, ``version``, any key ending in ``_wall_s`` or ``_seconds``, and
  every string with the output folder's path in it, that path replaced by ``OUT``;
- history.csv: the columns ``wall_time``, ``wall_s``, ``elapsed_s``;
- log files (``*.log``, ``log.*``): LIGGGHTS' and the host's logs carry timings;
- gzip headers (the time a ``.gz`` was written): a ``.gz`` is compared by its contents.
Everything else (collision logs, VTK files, pictures, scene.json, checkpoints) is compared as bytes.
The folder is ``out/same_outputs/`` (``ref/`` and ``now/``; the pour's dumps in ``pour/``), outside git;
$SAME_OUTPUTS_DIR moves it (references taken by a pristine checkout of the commit before).
"""
from __future__ import annotations

import argparse
import csv
import gzip
import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HERE = Path(os.environ.get("SAME_OUTPUTS_DIR", ROOT / "out" / "same_outputs"))
PYTHON = ROOT / ".venv" / "bin" / "python"
CASES = ("two-particles", "hot-cold-box", "wall-impact", "hot-cold-bed", "packed-bed-ergun", "silo-heat")
MPI_CASES = ("hot-cold-box", "wall-impact")       # also on two MPI ranks: each rank moves its collisions' heat
CLOCK_KEYS = {"elapsed_s", "wall_time_s", "wall_s", "seconds", "started", "finished", "host", "version",
              "wall_seconds", "elapsed"}
CLOCK_COLUMNS = {"wall_time", "wall_s", "elapsed_s"}

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


def pour() -> Path:
    """The dumps of tests/conftest.py's 60-particle pour, written once (inputs, not outputs)."""
    folder = HERE / "pour"
    if (folder / "done").exists():
        return folder
    sys.path.insert(0, str(ROOT / "tests"))
    from conftest import FLOOR_STL, POUR_SCRIPT, steel_toml
    shutil.rmtree(folder, ignore_errors=True)
    (folder / "post").mkdir(parents=True)
    (folder / "floor.stl").write_text(FLOOR_STL)
    local = lambda c: " ".join(f"c_{c}[{k}]" for k in range(1, 17))
    (folder / "in.pour").write_text(POUR_SCRIPT.format(pair=local("cp"), wall=local("cw")))
    subprocess.run(["liggghts", "-in", "in.pour", "-log", "log.liggghts", "-screen", "/dev/null"], cwd=folder,
                   check=True, timeout=600)
    wall = '\n[[walls]]\nfix = "walls"\nmaterial = "steel"\ntemperature = 350.0\n'
    (folder / "scene.toml").write_text(GLASS + "\n" + steel_toml() + wall)
    (folder / "own.toml").write_text(GLASS.replace("types = [1, 2]", "types = [1, 2]\ntemperature = 300"))
    (folder / "done").write_text("")
    return folder


def post_jobs(p: Path) -> dict:
    d = p / "post"
    contacts = ["--contacts", *sorted(map(str, d.glob("pair.*"))), *sorted(map(str, d.glob("wall.*")))]
    dumps = sorted(map(str, d.glob("dump.*")))
    return {
        "post-script": [*dumps, "--scene", p / "scene.toml", *contacts, "--script", p / "in.pour"],
        "post-options": [*dumps, "--scene", p / "scene.toml", *contacts, "--dt", "1e-5", "--compute",
                         "cp pair/gran/local delta id vel pos", "--compute", "cw wall/gran/local vel id pos delta"],
        "post-positions": [d / "fine.dump", "--scene", p / "own.toml", "--dt", "1e-5", "--model", "B"],
        "post-positions-script": [d / "all.dump", "--scene", p / "scene.toml", "--script", p / "in.pour"],
        "post-vtk": [*sorted(map(str, d.glob("p_*.vtk"))), "--scene", p / "own.toml", "--script", p / "in.pour"],
        "post-dumps-temperatures": [*dumps, "--scene", p / "scene.toml", *contacts, "--script", p / "in.pour",
                                    "--temperatures", "dumps"],
    }


def run_all(into: Path, only=None) -> dict:
    """Every job's exit code and stderr's last line, its output in ``into/NAME``."""
    into.mkdir(parents=True, exist_ok=True)
    status = {}
    for case in CASES:
        if only and case not in only:
            continue
        out = into / case
        shutil.rmtree(out, ignore_errors=True)
        r = subprocess.run([str(PYTHON), "-m", "pyhost", "run", str(ROOT / "cases" / case), "--test", "--out", str(out)],
                           cwd=ROOT, capture_output=True, text=True, timeout=1800)
        status[case] = (r.returncode, r.stderr.strip().splitlines()[-1:] if r.returncode else [])
        (out / "root").write_text(str(ROOT))
        print(f"{case}: exit {r.returncode}", flush=True)
    for case in MPI_CASES:
        name = f"{case}-mpi2"
        if only and name not in only:
            continue
        out = into / name
        shutil.rmtree(out, ignore_errors=True)
        r = subprocess.run(["mpirun", "--allow-run-as-root", "--oversubscribe", "-np", "2", str(PYTHON), "-m", "pyhost",
                            "run", str(ROOT / "cases" / case), "--test", "--out", str(out)],
                           cwd=ROOT, capture_output=True, text=True, timeout=1800)
        status[name] = (r.returncode, r.stderr.strip().splitlines()[-1:] if r.returncode else [])
        (out / "root").write_text(str(ROOT))
        print(f"{name}: exit {r.returncode}", flush=True)
    p = pour()
    for name, args in post_jobs(p).items():
        if only and name not in only:
            continue
        out = into / name
        shutil.rmtree(out, ignore_errors=True)
        r = subprocess.run([str(PYTHON), "-m", "pyhost", "post", *map(str, args), "--out", str(out)], cwd=ROOT,
                           capture_output=True, text=True, timeout=1800)
        status[name] = (r.returncode, r.stderr.strip().replace(str(out), "OUT").splitlines())
        (out / "root").write_text(str(ROOT))
        print(f"{name}: exit {r.returncode}", flush=True)
    return status


def scrub_json(value):
    if isinstance(value, dict):
        return {k: scrub_json(v) for k, v in value.items()
                if k not in CLOCK_KEYS and not k.endswith(("_wall_s", "_seconds"))}
    if isinstance(value, list):
        return [scrub_json(v) for v in value]
    return value


def comparable(path: Path, top: Path, root: str) -> bytes | None:
    """The bytes of a file as compared (None: not compared); the output folder ``top`` and the
    checkout ``root`` the run was made from written as OUT and ROOT."""
    name = path.name
    if name.endswith(".log") or name.startswith("log."):
        return None
    data = path.read_bytes()
    if name.endswith(".gz"):
        data = gzip.decompress(data)        # (gzip's header holds the time it was written)
    data = data.replace(str(top).encode(), b"OUT").replace(str(HERE).encode(), b"HERE")
    data = data.replace(root.encode(), b"ROOT")
    if name == "summary.json":
        return json.dumps(scrub_json(json.loads(data)), indent=1, sort_keys=True).encode()
    if name in ("history.csv", "history.csv.gz"):
        text = data.decode()
        rows = list(csv.reader(io.StringIO(text)))
        if rows:
            keep = [k for k, c in enumerate(rows[0]) if c not in CLOCK_COLUMNS]
            return "\n".join(",".join(r[k] for k in keep if k < len(r)) for r in rows).encode()
    return data


def root_of(folder: Path) -> str:
    """The checkout a job's outputs were made from (its ``root``, written with them)."""
    return (folder / "root").read_text().strip() if (folder / "root").exists() else str(ROOT)


def compare(ref: Path, now: Path) -> list:
    problems = []
    names = sorted({p.relative_to(ref) for p in ref.rglob("*") if p.is_file() and p.name != "root"}
                   | {p.relative_to(now) for p in now.rglob("*") if p.is_file() and p.name != "root"})
    for rel in names:
        a, b = ref / rel, now / rel
        top_a, top_b = ref / rel.parts[0], now / rel.parts[0]
        if not a.exists() or not b.exists():
            problems.append(f"{rel}: only in {'now' if b.exists() else 'ref'}")
            continue
        x, y = comparable(a, top_a, root_of(top_a)), comparable(b, top_b, root_of(top_b))
        if x != y:
            problems.append(f"{rel}: differs")
    return problems


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--save", action="store_true", help="write the references (before a change)")
    ap.add_argument("--only", nargs="*", help="these cases / post jobs only")
    ap.add_argument("--compare-only", action="store_true", help="compare the outputs already in now/")
    a = ap.parse_args()
    target = HERE / ("ref" if a.save else "now")
    if not a.compare_only:
        status = run_all(target, a.only)
        stat_file = target / "status.json"
        old = json.loads(stat_file.read_text()) if stat_file.exists() else {}
        stat_file.write_text(json.dumps(old | status, indent=1, sort_keys=True).replace(str(HERE), "HERE")
                             .replace(str(ROOT), "ROOT"))
    if a.save:
        return 0
    problems = compare(HERE / "ref", HERE / "now")
    if a.only:
        problems = [p for p in problems if p.split("/")[0].split(":")[0] in set(a.only) | {"status.json"}]
    print("\n".join(problems) if problems else "same: every output file equals its reference")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
