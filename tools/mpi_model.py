"""A scaling model of a dry run with collision heat on R MPI ranks, built from per-rank costs
measured on this machine (1 and 2 ranks), and projected to 64 ranks (docs/mpi.md, "A scaling
model").

What it measures, on the granular gas of cases/hot-cold-box grown to N particles at its packing
(as tools/bench_scaling.py), each in a fresh process, one after the other:
- plain LIGGGHTS (``liggghts -in``, the input the host writes for the scene) on 1 and 2 ranks for
  ``--steps`` steps: its own breakdown (Pair, Neigh, Comm, Other seconds), the atoms each rank
  owns and the ghost atoms it holds (LIGGGHTS' Nlocal and Nghost);
- the host with collision heat A (fast path) and without, on 1 and 2 ranks
  (tools/bench_scaling.py's worker): wall time, the time inside LIGGGHTS' runs on rank 0 and the
  collisions.

The model, per DEM step [s], for N particles on R ranks (a 3-d grid of subdomains as LIGGGHTS
chooses it: the least cut area):

    T(R) = c_atom N / R                      compute: Pair + Neigh + Other of the 1-rank run per atom
         + c_ghost G(R)                      halo: Comm per ghost atom (1 rank: periodic images)
         + m(R) lat                          messages: 2 per cut direction and step
         + c_rec N / R                       recording the contact events inside LIGGGHTS' steps
         + h_rank K / R                      heat moved on each rank, per collision K per step
         + h_root K                          rank 0 alone: joining the events, the collision log
         + h_plain(R)                        the host's fixed cost per step (plain host - native)

G(R), the ghost atoms of one subdomain, is counted from the geometry: the number density times
the subdomain's shell of width ``cutoff`` (the largest contact distance and the neighbour skin),
scaled by LIGGGHTS' own Nghost over that count on 1 rank (the gas is placed on a lattice that
leaves the box's faces thinner than its mean); the 2-rank count checks it. ``lat`` is the time one message costs:
fitted from the 2-rank Comm time on this machine (shared memory); on a cluster's network it is
larger (``--latency`` projects with another value). h_rank and h_root come from the heat-on
host on 1 and 2 ranks: on one rank both are paid, on two rank 0 pays h_root K + h_rank K / 2.

Two points fit two unknowns exactly: the model is checked only where it was fitted; the 64-rank
column is a projection, not a measurement. Read it for what would limit, not to the per cent.

Run: .venv/bin/python tools/mpi_model.py [--particles 100000] [--steps 1000]
     [--project 1000000] [--latency 2e-6] [--save FILE | --load FILE]
"""
from __future__ import annotations

import argparse
import json
import math
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_host import CASE, scaled, variant  # noqa: E402
from bench_scaling import ENV, measure  # noqa: E402

RANKS = (1, 2, 4, 8, 16, 32, 64)
BREAKDOWN = re.compile(r"^(Pair|Neigh|Comm|Outpt|Modify|Other)\s+time \(%\) = (\S+)", re.M)
PER_RANK = re.compile(r"^(Nlocal|Nghost):\s+(\S+) ave", re.M)


def native(n: int, steps: int, ranks: int, work: Path) -> dict:
    """Plain LIGGGHTS on the grown gas: its breakdown [s] of the last run and Nlocal, Nghost."""
    from pyhost.engines.liggghts.box_input import input_lines, place_particles, write_data
    from pyhost.scene import load_scene

    sc = scaled(load_scene(CASE), n)
    sc = variant(sc, steps * sc.time.dem_step, contact_heat="none")
    out = work / f"native-{n}-{ranks}"
    out.mkdir(parents=True, exist_ok=True)
    data = write_data(out / "particles.data", sc, place_particles(sc))
    (out / "in.native").write_text("\n".join(input_lines(sc, data.name) + ["run 0", f"run {steps}"]) + "\n")
    cmd = [shutil.which("liggghts"), "-in", "in.native", "-log", "log.native", "-screen", "/dev/null"]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd
    subprocess.run(cmd, cwd=out, env=ENV, check=True)
    log = (out / "log.native").read_text()
    last = log[log.rindex("Loop time"):]
    row = {k: float(v) for k, v in BREAKDOWN.findall(last)}
    row.update({k: float(v) for k, v in PER_RANK.findall(last)})
    row.update(particles=n, ranks=ranks, steps=steps)
    shutil.rmtree(out)
    return row


def geometry(n: int) -> dict:
    """The grown gas's box [m], its number density [1/m^3] and the ghost cut-off [m]."""
    from pyhost.engines.liggghts.box_input import input_lines
    from pyhost.scene import load_scene

    sc = scaled(load_scene(CASE), n)
    box = sc.domain.box
    lengths = [box[1] - box[0], box[3] - box[2], box[5] - box[4]]
    skin = next(float(line.split()[1]) for line in input_lines(sc, Path("x")) if line.startswith("neighbor "))
    r_max = max(g.radius for g in sc.particles)
    return dict(lengths=lengths, density=n / math.prod(lengths), cutoff=2.0 * r_max + skin)


def grid(ranks: int, lengths) -> tuple[int, int, int]:
    """LIGGGHTS' (LAMMPS') processor grid: the factorisation with the least cut area."""
    best = None
    for px in range(1, ranks + 1):
        if ranks % px:
            continue
        for py in range(1, ranks // px + 1):
            if (ranks // px) % py:
                continue
            pz = ranks // px // py
            sx, sy, sz = lengths[0] / px, lengths[1] / py, lengths[2] / pz
            area = sx * sy + sy * sz + sx * sz
            if best is None or area < best[0]:
                best = (area, (px, py, pz))
    return best[1]


def ghosts(ranks: int, geo: dict) -> tuple[float, int]:
    """Ghost atoms of one subdomain (the shell of width cutoff around it, the box periodic) and
    the messages it sends per step (the forward communication of positions and velocities: one
    swap to each side of a direction that is cut; the input has ``newton off``, so no reverse
    communication of forces; a direction of one subdomain copies its own periodic images)."""
    p = grid(ranks, geo["lengths"])
    side = [L / q for L, q in zip(geo["lengths"], p)]
    c = geo["cutoff"]
    shell = math.prod(s + 2 * c for s in side) - math.prod(side)
    messages = sum(2 for q in p if q > 1)
    return geo["density"] * shell, messages


def fit(rows: dict, geo: dict) -> dict:
    """The model's constants from the 1- and 2-rank measurements."""
    n1, n2 = rows["native"]["1"], rows["native"]["2"]
    steps = n1["steps"]
    n = n1["particles"]
    compute = (n1["Pair"] + n1["Neigh"] + n1.get("Modify", 0.0) + n1["Other"]) / steps
    c_atom = compute / n
    c_ghost = n1["Comm"] / steps / n1["Nghost"]
    g2, m2 = ghosts(2, geo)
    lat = max(n2["Comm"] / steps - c_ghost * n2["Nghost"], 0.0) / m2
    h1, h2 = rows["host"]["1"], rows["host"]["2"]
    K = h1["A"]["collisions"] / h1["A"]["steps"]

    def host_per_step(r):               # rank 0's time outside LIGGGHTS' runs, per step
        return (r["wall"] - r["in_dem"]) / r["steps"]

    plain1, plain2 = host_per_step(h1["none"]), host_per_step(h2["none"])
    heat1 = host_per_step(h1["A"]) - plain1           # = (h_rank + h_root) K
    heat2 = host_per_step(h2["A"]) - plain2           # = (h_rank / 2 + h_root) K
    c_rec = max((h1["A"]["in_dem"] / h1["A"]["steps"] - h1["none"]["in_dem"] / h1["none"]["steps"]) / n, 0.0)
    h_rank = max(2.0 * (heat1 - heat2), 0.0) / K
    h_root = max(heat1 / K - h_rank, 0.0)
    scale = n1["Nghost"] / ghosts(1, geo)[0]
    return dict(c_atom=c_atom, c_ghost=c_ghost, lat=lat, ghost_scale=scale, c_rec=c_rec, h_rank=h_rank, h_root=h_root, K_per_atom=K / n,
                h_plain1=plain1, h_plain2=plain2, ghost_formula_1=ghosts(1, geo)[0], ghost_formula_2=g2,
                ghost_liggghts_1=n1["Nghost"], ghost_liggghts_2=n2["Nghost"],
                native_step_1=sum(n1[k] for k in ("Pair", "Neigh", "Comm", "Other")) / steps,
                native_step_2=sum(n2[k] for k in ("Pair", "Neigh", "Comm", "Other")) / steps)


def project(p: dict, n: int, latency: float | None) -> list[dict]:
    geo = geometry(n)
    K = p["K_per_atom"] * n
    lat = p["lat"] if latency is None else latency
    out = []
    for r in RANKS:
        g, m = ghosts(r, geo)
        terms = dict(compute=p["c_atom"] * n / r, halo=p["c_ghost"] * p["ghost_scale"] * g, messages=m * lat,
                     record=p["c_rec"] * n / r, heat_ranks=p["h_rank"] * K / r, rank0=p["h_root"] * K,
                     host_fixed=p["h_plain1"] if r == 1 else p["h_plain2"])
        out.append(dict(ranks=r, grid=grid(r, geo["lengths"]), ghosts=g, total=sum(terms.values()), **terms))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--particles", type=int, default=100000, help="the measured size (1 and 2 ranks)")
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--project", type=int, nargs="+", default=[100000, 1000000], help="sizes to project")
    ap.add_argument("--latency", type=float, help="seconds per message instead of the fitted one (a cluster's network)")
    ap.add_argument("--save", type=Path, help="write the measurements to this JSON file")
    ap.add_argument("--load", type=Path, help="take the measurements from this JSON file instead of measuring")
    args = ap.parse_args()
    if args.load:
        rows = json.loads(args.load.read_text())
    else:
        rows = dict(native={}, host={})
        with tempfile.TemporaryDirectory() as tmp:
            for r in (1, 2):
                print(f"measuring {args.particles} particles on {r} rank(s) ...", flush=True)
                rows["native"][str(r)] = native(args.particles, args.steps, r, Path(tmp))
                dt = scaled(__import__("pyhost.scene", fromlist=["load_scene"]).load_scene(CASE), 1000).time.dem_step
                rows["host"][str(r)] = {h: measure(args.particles, r, args.steps * dt, h, Path(tmp))
                                        for h in ("none", "A")}
        if args.save:
            args.save.write_text(json.dumps(rows, indent=1))
    geo = geometry(rows["native"]["1"]["particles"])
    p = fit(rows, geo)
    print("\nMeasured (per DEM step) and fitted constants:")
    print(f"  native LIGGGHTS: {1e3 * p['native_step_1']:.3f} ms on 1 rank, {1e3 * p['native_step_2']:.3f} ms on 2")
    print(f"  compute per atom c_atom = {1e9 * p['c_atom']:.1f} ns; per ghost atom c_ghost = {1e9 * p['c_ghost']:.1f} ns; "
          f"per message lat = {1e6 * p['lat']:.2f} us; recording events per atom c_rec = {1e9 * p['c_rec']:.1f} ns")
    print(f"  ghosts per rank: formula x {p['ghost_scale']:.3f} {p['ghost_scale'] * p['ghost_formula_1']:.0f} / "
          f"{p['ghost_scale'] * p['ghost_formula_2']:.0f}, LIGGGHTS "
          f"{p['ghost_liggghts_1']:.0f} / {p['ghost_liggghts_2']:.0f} (1 / 2 ranks)")
    print(f"  collisions per atom and step {p['K_per_atom']:.3g}; heat per collision on the ranks h_rank = "
          f"{1e6 * p['h_rank']:.2f} us, on rank 0 alone h_root = {1e6 * p['h_root']:.2f} us")
    print(f"  the host's fixed cost per step: {1e3 * p['h_plain1']:.3f} ms (1 rank), {1e3 * p['h_plain2']:.3f} ms (2)")
    for n in args.project:
        print(f"\nProjection, {n} particles, ms per step"
              + (f" (message latency {1e6 * args.latency:g} us)" if args.latency else "") + ":")
        print(f"{'ranks':>5} | {'grid':>8} | {'compute':>8} | {'halo':>7} | {'messages':>8} | {'record':>7} | {'heat/R':>7} | "
              f"{'rank 0':>7} | {'fixed':>6} | {'total':>7} | {'speed-up':>8} | {'limit':>10}")
        rows_p = project(p, n, args.latency)
        for row in rows_p:
            terms = {k: row[k] for k in ("compute", "halo", "messages", "record", "heat_ranks", "rank0", "host_fixed")}
            limit = max(terms, key=terms.get)
            print(f"{row['ranks']:>5} | {'x'.join(map(str, row['grid'])):>8} | {1e3 * row['compute']:8.3f} | "
                  f"{1e3 * row['halo']:7.3f} | {1e3 * row['messages']:8.3f} | {1e3 * row['record']:7.3f} | {1e3 * row['heat_ranks']:7.3f} | "
                  f"{1e3 * row['rank0']:7.3f} | {1e3 * row['host_fixed']:6.3f} | {1e3 * row['total']:7.3f} | "
                  f"{rows_p[0]['total'] / row['total']:8.2f} | {limit:>10}")


if __name__ == "__main__":
    main()
