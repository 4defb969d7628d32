"""Benchmarks of the coupled fluidized bed (cases/hot-cold-bed: 3000 beads, collheatFoam).

Wall time counts the coupled run from its first DEM step, not starting the engines (fluid
mesh and solver launch, LIGGGHTS and its input: about 1 s per run), minus the benchmark's
own recording.

1. What each effect costs, from the case's initial placement (a loose jittered lattice
   that the fluid carries only in part: it settles during the first tens of ms, with fewer
   collisions than the bubbling bed has later), ``--time`` of bed time per run: wall
   seconds per simulated second of the plain DEM without fluid (dry and isothermal: the
   bed just falls onto the floor), the fluid alone (isothermal), then fluid with collision
   heat A on the fast path (the case as shipped), on the exact path, with restitution
   feedback, with enduring conduction; best of ``--repeat`` runs, and the collisions
   counted (runs that extract no contacts count none).

2. What the coupling interval costs in accuracy. ``time.couple_every`` sets both how often
   particles and fluid exchange forces and the fluid's own time step (one collheatFoam step
   per interval): both errors are in the comparison. Each interval runs the case as shipped
   for ``--time`` and is compared with the smallest interval (``--reference``, default every
   DEM step) from the same state: (a) the initial placement, (b) the bubbling bed after
   ``--start`` of bed time (the shipped case run isothermally up to then; every run then
   restarts from those positions and velocities (``simulate(..., start=particles)``), with
   spins, contact histories and the fluid reset: a fresh fluid at rest, as at t = 0; the
   contacts present at the restart count as open, not as collisions). Metrics, at ``--compare`` after the
   start (a few ms: before chaos has decorrelated the runs):
   - dv/v: RMS over particles of |v - v_ref| over the RMS of |v_ref|: how far the
     particle motions have moved apart. A granular flow is chaotic: any difference grows,
     and two decorrelated runs give dv/v of about sqrt(2) whatever their interval; from
     then on only statistical quantities compare. The twin row is the reference again
     with every particle moved by up to 1 nm: how fast a difference grows by chaos alone,
     so how long the trajectories stay comparable, and the run-to-run noise of the other
     metrics once they are not. dv/v against time is printed too;
   - F_z: the fluid's vertical force on all particles (drag and pressure gradient, as
     the DEM receives it), averaged over the second half of the comparison time (the
     first half holds the fluid's start from rest, which the DEM feels one interval late):
     the momentum the fluid gave the bed per unit time, in % of the bed weight (which a
     fluidized bed's fluid carries); its error is in % of the weight as well. Averaged,
     because a particle crossing into another cell changes the fluid fraction at once,
     which gives one-step pressure spikes that grow as the fluid step shrinks: a snapshot
     would compare the spikes;
   - dp: mean pressure of the lowest cell layer (in the plenum) minus that of the highest
     (below the outlet), averaged like F_z: the bed's resistance to the air,
     about weight / floor area once fluidized; its error in % of the reference;
   - Q: total heat moved between particles from the start, and N: collisions counted;
     both cumulative, errors in % of the reference (n/a while the reference has none).

``--fluid-step`` prints instead what the fluid step alone does, without the DEM: the
particles frozen at the initial placement, the fluid's steady force on them and pressure
drop with each interval's step and with a tenth of the smallest (sub-steps).

Run: .venv/bin/python tools/bench_bed.py [--time 0.03] [--start 0.15] [--compare 0.004] [--repeat 2]
LIGGGHTS prints style-table warnings on stderr when it loads: ``2>/dev/null`` hides them.
"""
from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from pathlib import Path

import numpy as np

from bench_host import Clocked
from pyhost.world import simulate, start_fluid
from pyhost.engines.liggghts.box_input import place_particles
from pyhost.effects.fluid import layer_pressure_drop, upwards
from pyhost.output import read_collisions
from pyhost.scene import load_scene

CASE = Path(__file__).resolve().parents[1] / "cases" / "hot-cold-bed" / "case.toml"
INTERVALS = (5, 10, 25, 50, 100)
STRIDE = max(INTERVALS)             # DEM steps between velocity snapshots: every interval divides it


def variant(scene, end, couple_every=None, **effects):
    return dataclasses.replace(
        scene, effects=dataclasses.replace(scene.effects, **effects),
        time=dataclasses.replace(scene.time, end=end, couple_every=couple_every or scene.time.couple_every),
        output=dataclasses.replace(scene.output, vtk=False, pictures=False, every=end))


class Probe:
    """The started fluid as the loop sees it, recording at every coupling the fluid's total
    force on the particles and the pressure drop over the mesh, and every ``snap``-th
    coupling the particle positions and velocities; ``count`` adds the collisions and heat
    moved so far to each snapshot after the run. ``overhead``: seconds spent recording."""

    def __init__(self, fluid, snap: int, dt: float):
        self.fluid, self.snap, self.dt = fluid, snap, dt
        self.F, self.dp, self.snaps, self.overhead = [], [], [], 0.0

    def __getattr__(self, name):
        return getattr(self.fluid, name)

    def couple(self, x, v, d, duration: float, steps: int = 1) -> np.ndarray:
        forces = self.fluid.particle_forces(x, v, d)
        t0 = time.perf_counter()
        if len(self.F) % self.snap == 0:
            self.snaps.append({"t": len(self.F) * self.dt, "x": np.array(x, copy=True), "v": np.array(v, copy=True)})
        self.F.append(forces[:, 2].sum())
        self.dp.append(layer_pressure_drop(self.fluid, upwards(self.fluid)))
        self.overhead += time.perf_counter() - t0
        self.fluid.advance(duration, steps)
        return forces

    def count(self, out: Path) -> None:
        """N: collisions, Q: heat moved between particles [J] (sum of |Q|) up to each snapshot
        (the run's collision log in ``out``, CSV or binary)."""
        c = read_collisions(out)
        for s in self.snaps:
            upto = c["time"] <= s["t"] * (1 + 1e-9)
            s["N"] = int(upto.sum())
            s["Q"] = float(np.abs(c["Q"][upto & (c["wall"] == 0)]).sum())


def run(scene, out: Path, particles=None, record: bool = False, nudge: float = 0.0):
    """Run ``scene`` from ``particles`` (default: its initial placement, else a restart),
    every position moved by up to ``nudge`` [m]. Returns the wall time of the coupled run
    (less recording), its summary, the probe (``record``, fluid runs) and the particles at
    the end (``record``)."""
    particles_at_start = particles if particles is not None else place_particles(scene)
    if nudge:
        moved = np.random.default_rng(1).uniform(-nudge, nudge, particles_at_start.position.shape)
        particles = dataclasses.replace(particles_at_start, position=particles_at_start.position + moved)
    k = scene.time.couple_every
    engines = {}

    def wrap(dem):
        engines["dem"] = Clocked(dem)
        return engines["dem"]

    def wrap_fluid(fluid):
        engines["fluid"] = Probe(fluid, STRIDE // k, k * scene.time.dem_step)
        return engines["fluid"]

    summary = simulate(scene, out.resolve(), progress_every=1e9, wrap=wrap, start=particles,
                       wrap_fluid=wrap_fluid if record else None)
    probe = engines.get("fluid")
    wall = time.perf_counter() - engines["dem"].started - (probe.overhead if probe else 0.0)
    final = None
    if probe:
        probe.count(out)
        last = probe.snaps[-1]           # the run ends on a snapshot: its time is a multiple of STRIDE;
        # in particle order: box scenes keep LIGGGHTS' local order (atom_modify sort 0 0, one process)
        final = dataclasses.replace(particles_at_start, position=last["x"], velocity=last["v"])
    return wall, summary, probe, final


def rms(v) -> float:
    return float(np.sqrt(np.mean(np.sum(v**2, axis=1))))


def at(probe: Probe, t: float) -> dict:
    """The probe's snapshot at bed time ``t`` after its start, with F and dp averaged over
    the second half of that time (after the fluid's start from rest)."""
    s = probe.snaps[int(np.argmin([abs(s["t"] - t) for s in probe.snaps]))]
    calls = round(s["t"] / probe.dt)
    window = slice(calls // 2, calls)
    return dict(s, F=float(np.mean(probe.F[window])), dp=float(np.mean(probe.dp[window])))


def errors(ref: dict, got: dict, weight: float) -> dict:
    def rel(key):
        return f"{100 * (got[key] / ref[key] - 1):+.2f}" if ref[key] else "n/a"
    return {"dv": rms(got["v"] - ref["v"]) / rms(ref["v"]), "F": 100 * (got["F"] - ref["F"]) / weight,
            "dp": rel("dp"), "Q": rel("Q"), "N": rel("N")}


def interval_table(base, end: float, compare: float, reference: int, weight: float, out: Path, particles=None):
    """Table 2 from ``particles`` (default the initial placement): one run per interval."""
    dt = base.time.dem_step
    probes, walls = {}, {}
    labels = {reference: f"{reference} (ref)", "twin": f"{reference}, 1 nm"}
    for k in (reference, *INTERVALS, "twin"):
        every = reference if k == "twin" else k
        walls[k], _, probes[k], _ = run(variant(base, end, couple_every=every), out / f"couple{k}", particles,
                                        record=True, nudge=1e-9 if k == "twin" else 0.0)
    r0 = at(probes[reference], compare)
    print(f"reference, {r0['t'] * 1e3:.1f} ms from the start: mean F_z (second half) "
          f"{100 * r0['F'] / weight:.1f} % of the weight, mean dp {r0['dp']:.0f} Pa, Q {r0['Q']:.3g} J, "
          f"N {r0['N']}, RMS |v| {rms(r0['v']):.3g} m/s")
    print(f"{'every k steps':>13} | {'wall s/sim s':>12} | {'dv/v':>6} | {'F_z err %W':>10} | "
          f"{'dp err %':>8} | {'Q err %':>7} | {'N err %':>7}")
    for k, probe in probes.items():
        if k == reference:
            print(f"{labels[k]:>13} | {walls[k] / end:12.0f} |")
            continue
        e = errors(r0, at(probe, compare), weight)
        print(f"{labels.get(k, k):>13} | {walls[k] / end:12.0f} | {e['dv']:6.3f} | {e['F']:+10.2f} | "
              f"{e['dp']:>8} | {e['Q']:>7} | {e['N']:>7}")
    times = [STRIDE * dt * 2**j for j in range(20) if STRIDE * dt * 2**j < end * (1 - 1e-9)] + [end]
    print("dv/v against bed time from the start (about 1.41: decorrelated)")
    print(f"{'ms':>13} | " + " ".join(f"{t * 1e3:6.1f}" for t in times))
    for k, probe in probes.items():
        if k != reference:
            print(f"{labels.get(k, k):>13} | " + " ".join(
                f"{rms(at(probe, t)['v'] - at(probes[reference], t)['v']) / rms(at(probes[reference], t)['v']):6.3f}"
                for t in times))


def fluid_step_table(base, weight: float, out: Path, end: float = 0.004) -> None:
    """The fluid step alone: particles frozen at the initial placement, the fluid run to its
    steady state with each coupling interval's step, and with a tenth of the smallest."""
    dt = base.time.dem_step
    p = place_particles(base)
    print(f"fluid step alone: particles frozen at the initial placement, steady state after {end * 1e3:g} ms")
    print(f"{'fluid step [s]':>14} | {'F_z %W':>6} | {'dp [Pa]':>7}")
    for k, substeps in ((100, 1), (25, 1), (5, 1), (1, 1), (1, 10)):
        fluid = start_fluid(variant(base, end, couple_every=k), out / f"frozen{k}-{substeps}")
        try:
            for _ in range(round(end / (k * dt))):
                fluid.couple(p.position, p.velocity, 2.0 * p.radius, k * dt, substeps)
            F = fluid.particle_forces(p.position, p.velocity, 2.0 * p.radius)[:, 2].sum()
            print(f"{k * dt / substeps:14.1e} | {100 * F / weight:6.1f} | {layer_pressure_drop(fluid, upwards(fluid)):7.1f}", flush=True)
        finally:
            fluid.stop()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--time", type=float, default=0.03, help="simulated time per run [s]")
    ap.add_argument("--start", type=float, default=0.15, help="bed time of table 2b's start [s]; 0: no 2b")
    ap.add_argument("--compare", type=float, default=0.004, help="table 2's comparison, after the start [s]")
    ap.add_argument("--reference", type=int, default=1, help="coupling interval of the reference [DEM steps]")
    ap.add_argument("--repeat", type=int, default=2, help="runs per row of table 1 (best of)")
    ap.add_argument("--effects-only", action="store_true", help="table 1 only")
    ap.add_argument("--fluid-step", action="store_true",
                    help="instead of the tables: the fluid step's effect on a frozen bed (about 1 min)")
    args = ap.parse_args()
    started = time.perf_counter()
    base = load_scene(CASE)
    dt = base.time.dem_step
    particles = place_particles(base)
    weight = float(np.sum(particles.mass)) * abs(base.domain.gravity[2])
    area = (base.domain.box[1] - base.domain.box[0]) * (base.domain.box[3] - base.domain.box[2])
    end = max(1, round(args.time / (STRIDE * dt))) * STRIDE * dt
    compare = min(max(1, round(args.compare / (STRIDE * dt))) * STRIDE * dt, end)
    print(f"scene: {CASE.parent.name}, {len(particles.radius)} particles, DEM step {dt:g} s, shipped "
          f"couple_every {base.time.couple_every}, {end:g} s simulated per run; "
          f"bed weight {weight:.4g} N = {weight / area:.0f} Pa over the floor")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if args.fluid_step:
            fluid_step_table(base, weight, tmp)
            return
        print(f"\n1. cost of each effect, from the initial placement (fluid coupled every "
              f"{base.time.couple_every} steps; best of {args.repeat})")
        print(f"{'effects':>40} | {'wall s per simulated s':>22} | collisions")
        rows = (("plain DEM, no fluid (isothermal)", {"fluid": False, "contact_heat": "none"}),
                ("fluid only (isothermal)", {"contact_heat": "none"}),
                ("fluid + heat A, fast path (shipped)", {"contact_heat": "A", "heat_path": "fast"}),
                ("fluid + heat A, exact path", {"contact_heat": "A", "heat_path": "exact"}),
                ("+ restitution feedback", {"contact_heat": "A", "heat_path": "fast", "restitution_feedback": True}),
                ("+ enduring conduction", {"contact_heat": "A", "heat_path": "fast",
                                           "restitution_feedback": True, "enduring_conduction": True}))
        for k, (name, eff) in enumerate(rows):
            runs = [run(variant(base, end, **eff), tmp / f"effects{k}-{r}") for r in range(args.repeat)]
            wall = min(r[0] for r in runs)
            count = runs[0][1]["collisions"] if eff["contact_heat"] != "none" else "-"
            print(f"{name:>40} | {wall / end:22.0f} | {count}", flush=True)
        if args.effects_only:
            return

        print(f"\n2a. coupling interval against every {args.reference} DEM step(s), from the initial placement")
        interval_table(base, end, compare, args.reference, weight, tmp / "a")
        if args.start > 0:
            t0 = max(1, round(args.start / (STRIDE * dt))) * STRIDE * dt
            print(f"\n2b. the same from the bed at t = {t0:g} s (isothermal, coupled every {base.time.couple_every})")
            wall, _, _, developed = run(variant(base, t0, contact_heat="none"), tmp / "prelude", record=True)
            print(f"(reaching it took {wall:.0f} s; RMS |v| there {rms(developed.velocity):.3g} m/s)")
            interval_table(base, end, compare, args.reference, weight, tmp / "b", developed)
    print(f"\nbenchmark run time {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
