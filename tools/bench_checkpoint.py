"""What checkpoints cost: wall time of a case's --test run without and with periodic checkpoints.

Runs the case (default cases/bed-25k: 25,000 spheres fluidized by the gas) ``--test`` once
without checkpoints and once with ``output.checkpoint`` set so that ``--count`` are written,
alternating, ``--repeat`` times each. Prints each run's wall time, the checkpoints' size and
write time (from the run's own ``checkpoint at ...`` lines), the overhead in this run and the
overhead a periodic interval would add to a full run, from the case's wall seconds per
simulated second measured here.

The machine is shared: compare only figures taken in one run, with nothing else running.

Run: .venv/bin/python tools/bench_checkpoint.py [CASE] [--count 5] [--repeat 2] [--interval 0.01 0.02 0.05]
"""
from __future__ import annotations

import argparse
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINE = re.compile(r"checkpoint at t = \S+ s \(step \d+\): \S+, ([\d.]+) MB, ([\d.]+) s")
RATE = re.compile(r"([\d.e+-]+) s simulated per s")


def with_checkpoint(toml: str, every: float) -> str:
    """case.toml's text with ``output.checkpoint = every`` (the section added if missing)."""
    toml = re.sub(r"(?m)^\s*checkpoint\s*=.*\n", "", toml)
    if re.search(r"(?m)^\[output\]\s*$", toml):
        return re.sub(r"(?m)^\[output\]\s*$", f"[output]\ncheckpoint = {every!r}", toml, count=1)
    return toml + f"\n[output]\ncheckpoint = {every!r}\n"


def run(case: Path, out: Path) -> tuple[float, list[tuple[float, float]], float]:
    """Wall seconds of ``pyhost run CASE --test``, its checkpoints' (MB, s) and the loop's last
    rate (simulated s per wall s, start-up left out)."""
    t = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "pyhost", "run", str(case), "--test", "--out", str(out), "--overwrite"],
                       cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if p.returncode:
        sys.exit(f"{case}: exit {p.returncode}\n{p.stderr[-2000:]}")
    rates = RATE.findall(p.stdout)
    return wall, [(float(a), float(b)) for a, b in LINE.findall(p.stdout + p.stderr)], float(rates[-1]) if rates else 0.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", default=str(ROOT / "cases" / "bed-25k"))
    ap.add_argument("--count", type=int, default=5, help="checkpoints written in the --test run")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--interval", type=float, nargs="+", default=[0.01, 0.02, 0.05],
                    help="periodic intervals (simulated s) whose overhead on a full run is printed")
    args = ap.parse_args()
    from pyhost.scene import load_scene

    case = Path(args.case).resolve()
    scene = load_scene(case / "case.toml")
    end = scene.time.test_end or scene.time.end / 10          # what --test runs (pyhost.commands.run.run_case)
    every = end / (args.count + 0.5)          # not at the end: the last one would not be a periodic cost
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        plain, ckpt = tmp / "plain", tmp / "ckpt"
        for folder in (plain, ckpt):
            shutil.copytree(case, folder, ignore=shutil.ignore_patterns("output", "post"))
        (ckpt / "case.toml").write_text(with_checkpoint((case / "case.toml").read_text(), every))
        walls = {"without": [], "with": []}
        written, rates = [], []
        for k in range(args.repeat):
            wall, _, rate = run(plain, tmp / "out-plain")
            walls["without"].append(wall)
            rates.append(rate)
            wall, lines, _ = run(ckpt, tmp / "out-ckpt")
            walls["with"].append(wall)
            written += lines
            print(f"repeat {k + 1}: {walls['without'][-1]:.2f} s without, {wall:.2f} s with {len(lines)} checkpoints",
                  flush=True)
    if not written:
        sys.exit("no checkpoint line in the run's output: nothing to measure")
    per = len(written) // args.repeat
    mb, sec = statistics.median(a for a, _ in written), statistics.median(b for _, b in written)
    w0, w1 = statistics.median(walls["without"]), statistics.median(walls["with"])
    per_sim = 1 / statistics.median(rates) if min(rates) > 0 else w0 / end
    print(f"\n{case.name} --test: {end:g} s simulated, {per} checkpoints every {every:.4g} s")
    print(f"  checkpoint: {mb:.3g} MB, {sec:.3g} s to write (median of {len(written)})")
    print(f"  run: {w0:.2f} s without, {w1:.2f} s with (median of {args.repeat}): +{100 * (w1 / w0 - 1):.1f} %, "
          f"{(w1 - w0) / per:.3g} s per checkpoint")
    print(f"  {per_sim:.0f} wall s per simulated s (the loop's rate, start-up left out)")
    cost = max((w1 - w0) / per, sec)
    for iv in args.interval:
        print(f"  checkpoint every {iv:g} s simulated: about {100 * cost / (iv * per_sim):.1f} % of a full run's time")


if __name__ == "__main__":
    main()
