"""The 3000-bead bed's heat cost on this code and on another checkout, in one run: wall time
per simulated second of the fluid alone and of fluid + collision heat A (fast path), from the
case's initial placement, best of ``--repeat``, alternating the two codes so that the load of
a shared machine falls on both alike. Each measurement runs tools/bench_bed.py's ``run`` of
its own checkout in a fresh process (the old code's API differs).

Run: .venv/bin/python tools/bench_bed_baseline.py --baseline /path/to/old/checkout [--time 0.03]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MEASURE = """
import inspect, json, sys
from pathlib import Path
sys.path.insert(0, sys.argv[1] + "/tools")
import bench_bed as b
from pyhost.scene import load_scene
base = load_scene(b.CASE)
effects = json.loads(sys.argv[3])
kwargs = {"fluid_on": True} if "fluid_on" in inspect.signature(b.run).parameters else {}
wall, summary = b.run(b.variant(base, float(sys.argv[2]), **effects), Path(sys.argv[4]), **kwargs)[:2]
print(json.dumps([wall, summary["collisions"]]))
"""


def measure(tree: Path, end: float, effects: dict, out: Path):
    r = subprocess.run([sys.executable, "-c", MEASURE, str(tree), str(end), json.dumps(effects), str(out)],
                       capture_output=True, text=True, env={"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin"},
                       cwd=tree)
    if r.returncode != 0:
        raise SystemExit(f"{tree}: {r.stderr[-2000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--baseline", type=Path, required=True, help="checkout of the old code")
    ap.add_argument("--time", type=float, default=0.03, help="simulated time per run [s]")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    rows = (("fluid only", {"contact_heat": "none"}), ("fluid + heat A", {"contact_heat": "A", "heat_path": "fast"}))
    best = {}
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(args.repeat):
            for code, tree in (("this", ROOT), ("baseline", args.baseline.resolve())):
                for name, eff in rows:
                    wall, count = measure(tree, args.time, eff, Path(tmp) / f"{code}-{name}-{rep}".replace(" ", ""))
                    key = (code, name)
                    best[key] = min(best.get(key, (float("inf"), 0)), (wall, count))
    print(f"hot-cold-bed, {args.time:g} s simulated per run, best of {args.repeat}, one run of this script")
    print(f"{'code':>9} | {'fluid only [wall s/s]':>21} | {'fluid + heat A [wall s/s]':>25} | ratio | collisions")
    for code in ("baseline", "this"):
        f, h = best[code, "fluid only"][0], best[code, "fluid + heat A"]
        print(f"{code:>9} | {f / args.time:21.0f} | {h[0] / args.time:25.0f} | {h[0] / f:5.2f} | {h[1]}")


if __name__ == "__main__":
    main()
