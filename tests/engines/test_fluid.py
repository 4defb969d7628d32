"""Fluid bridge and collheatFoam on the real engines: settling sphere, Ergun bed, serial
against two ranks, a diverging run."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from foamlib import FoamCase
from scipy.optimize import brentq

from plugins import drag
from pyhost.engines.fluid_case import box_case
from pyhost.engines.liggghts import Liggghts, granular_box
from pyhost.engines.openfoam import FluidError, FluidSolver

pytestmark = pytest.mark.engines

WATER = dict(rho=1000.0, nu=1e-6)                     # kg/m^3, m^2/s
WALLS = {f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")}
G = 9.81                                              # m/s^2


def settle(workdir, law: str) -> tuple[list, float]:
    """A 1 mm glass sphere released in still water, moved by LIGGGHTS with the fluid force
    from the bridge, in a closed box 3 x 3 x 20 cells of 4 mm: its falling speed at each
    coupling [m/s] and the fluid fraction around it at the end."""
    d, rho_p, cell = 1e-3, 2500.0, 4e-3                # m, kg/m^3, m
    dt_dem, every, steps = 1e-4, 10, 250               # s, DEM steps per coupling, couplings
    case = box_case(Path(workdir) / "fluid", lo=(0, 0, 0), hi=(3 * cell, 3 * cell, 20 * cell),
                    cells=(3, 3, 20), boundaries=WALLS, dt=every * dt_dem, **WATER)
    with Liggghts(Path(workdir) / "dem") as dem, FluidSolver(case, drag=law) as fluid:
        dem.commands(granular_box((0, 0, 0), (3 * cell, 3 * cell, 20 * cell), youngs=5e6,
                                  poisson=0.3, restitution=0.9, friction=0.5, skin=d / 2,
                                  dt=dt_dem))
        dem.commands(f"""
            create_atoms 1 single {1.5 * cell} {1.5 * cell} {18.5 * cell} units box
            set atom 1 diameter {d} density {rho_p}
            fix gravity all gravity {G} vector 0 0 -1
            fix fluid all external pf/array 1
            fix integrate all nve/sphere
        """)
        dem.run(0)
        # the set-up made fix external's array from uninitialised memory and took it as a force;
        # the first step (run ... pre no) would start from that force (the sphere, now and then,
        # left the box): zero it and set up again, as pyhost.engines.dem.Dem.prepare does
        dem.external_force("fluid")[:] = 0.0
        dem.commands("run 0")
        vz = []
        for k in range(steps):
            x, v = dem.atom("x").copy(), dem.atom("v").copy()
            force = fluid.couple(dem.atom("x"), dem.atom("v"), 2 * dem.atom("radius"),
                                 every * dt_dem)
            dem.external_force("fluid")[:] = force
            dem.run(every)
            if len(dem.atom("v")) == 0:     # say what it saw
                raise RuntimeError(f"the sphere left the box in coupling {k}: it was at x {x.tolist()} m, "
                                   f"v {v.tolist()} m/s, the fluid force {force.tolist()} N, fraction "
                                   f"{fluid.alpha.min()}")
            vz.append(float(-dem.atom("v")[0, 2]))
        return vz, float(fluid.alpha.min())


@pytest.mark.parametrize("law", ["difelice", "gidaspow"])
def test_sphere_settles_at_the_terminal_velocity_of_the_drag_law(tmp_path, law):
    """The settling sphere (``settle``), in a fresh process: the LIGGGHTS bridge tries
    commands in forked copies, which is safe only in a process no earlier test has used for
    LIGGGHTS (a second instance in a long test process once lost the sphere). The fluid
    around it is free to move (the sphere drags its cell's fluid along: about 1 % here)."""
    code = ("import json, sys; sys.path.insert(0, sys.argv[1]); import test_fluid as t; "
            "print(json.dumps(t.settle(sys.argv[2], sys.argv[3])))")
    r = subprocess.run([sys.executable, "-c", code, str(Path(__file__).parent), str(tmp_path), law],
                       capture_output=True, text=True, timeout=600, cwd=Path(__file__).resolve().parents[2])
    assert r.returncode == 0, r.stderr[-3000:]
    vz, alpha = json.loads(r.stdout.strip().splitlines()[-1])
    d, rho_p = 1e-3, 2500.0
    vp = np.pi * d**3 / 6
    weight = (rho_p - WATER["rho"]) * vp * G           # N, gravity less buoyancy
    law_k = drag.LAWS.lookup(law)
    v_terminal = brentq(lambda s: law_k(alpha, s, d, **WATER) * s - weight, 1e-6, 10.0)
    v_end = np.mean(vz[-20:])
    print(f"{law}: terminal {v_end:.5f} m/s, law {v_terminal:.5f} m/s, "
          f"error {v_end / v_terminal - 1:+.2%}")
    assert vz[-1] == pytest.approx(vz[-20], rel=1e-2)  # it is steady
    assert v_end == pytest.approx(v_terminal, rel=0.03)


def ergun_gradient(u_s, alpha, d, rho, nu):
    """Ergun (1952): pressure drop per length (Pa/m) across a packed bed at superficial
    velocity u_s (m/s), fluid fraction alpha, particle diameter d (m)."""
    return (150 * (1 - alpha)**2 * rho * nu * u_s / (alpha**3 * d**2)
            + 1.75 * (1 - alpha) * rho * u_s**2 / (alpha**3 * d))


@pytest.mark.parametrize("u_s", [2e-3, 2e-2])
def test_fixed_packed_bed_pressure_drop_matches_ergun(tmp_path, u_s):
    """Water up through a fixed simple-cubic bed of touching 2 mm spheres (fluid fraction
    1 - pi/6), 8 per 4 mm cell, between two particle-free layers; Gidaspow's law."""
    d, cell = 2e-3, 4e-3
    nz, bed = 16, range(4, 12)                          # cells, bed rows
    case = box_case(tmp_path / "bed", lo=(0, 0, 0), hi=(2 * cell, 2 * cell, nz * cell),
                    cells=(2, 2, nz), gravity=(0, 0, 0), dt=0.02,
                    boundaries={"xlo": "slip", "xhi": "slip", "ylo": "slip", "yhi": "slip",
                                "zlo": ("inlet", (0, 0, u_s)), "zhi": "outlet"}, **WATER)
    axis = (np.arange(2 * 2) + 0.5) * d                # two spheres per cell and axis
    x, y, z = np.meshgrid(axis, axis, (np.arange(2 * len(bed)) + 0.5) * d + bed[0] * cell,
                          indexing="ij")
    centres = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    with FluidSolver(case, drag="gidaspow") as fluid:
        for _ in range(40):
            fluid.couple(centres, np.zeros_like(centres), d, 0.02)
        p, _ = fluid.fields()
        zc = fluid.cell_centres[:, 2]
        alpha = fluid.alpha
        written = fluid.write()
    # What the solver wrote, read back with foamlib, is what the pipe gave.
    step = FoamCase(case)[-1]
    assert step.time == pytest.approx(written)
    assert np.allclose(np.asarray(step["p"].internal_field) * WATER["rho"], p, rtol=1e-8,
                       atol=1e-8 * np.abs(p).max())
    assert np.allclose(np.asarray(step["alpha"].internal_field), alpha, rtol=1e-8)
    inside = (zc > (bed[0] + 1) * cell) & (zc < (bed[-1]) * cell)
    assert np.allclose(alpha[inside], 1 - np.pi / 6, rtol=1e-12)
    slope = -np.polyfit(zc[inside], p[inside], 1)[0]    # Pa/m
    expected = ergun_gradient(u_s, 1 - np.pi / 6, d, **WATER)
    print(f"u_s = {u_s} m/s: dp/dz {slope:.2f} Pa/m, Ergun {expected:.2f} Pa/m, "
          f"error {slope / expected - 1:+.2%}")
    assert slope == pytest.approx(expected, rel=0.05)
    # Across the whole column, bed edges included: the drop of 8 cells of bed (the
    # cell-centred exchange of DPMFoam lost about one cell of it at the two edges).
    drop = p[zc == zc.min()].mean() - p[zc == zc.max()].mean()
    print(f"total drop {drop:.3f} Pa, Ergun over the bed {expected * len(bed) * cell:.3f} Pa")
    assert drop == pytest.approx(expected * len(bed) * cell, rel=0.01)


@pytest.mark.parametrize("ddt_alpha", [True, False])
def test_moving_particles_drive_the_gas_only_with_ddt_alpha(tmp_path, ddt_alpha):
    """A layer of 2 mm spheres (given at rest, so no drag) sinks one cell-fraction per step in a
    box closed below and open above. With d(alpha)/dt in continuity the fraction's change
    drives the displaced gas (its largest superficial speed the solids' own, 2 mm in 0.02 s:
    0.1 m/s, times their fraction pi/6, within 5 %); without it (``-noDdtAlpha``, CFDEM's default)
    nothing drives the gas: it stays at rest to round-off."""
    d, cell, dt = 2e-3, 4e-3, 0.02
    case = box_case(tmp_path / "box", lo=(0, 0, 0), hi=(2 * cell, 2 * cell, 12 * cell), cells=(2, 2, 12),
                    gravity=(0, 0, 0), dt=dt, boundaries={**WALLS, "zhi": "outlet"}, **WATER)
    axis = (np.arange(4) + 0.5) * d
    x, y, z = np.meshgrid(axis, axis, (np.arange(4) + 0.5) * d + 6 * cell, indexing="ij")
    centres = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    speeds = []
    with FluidSolver(case, drag="gidaspow", ddt_alpha=ddt_alpha) as fluid:
        for k in range(6):
            fluid.couple(centres - [0, 0, k * d], np.zeros_like(centres), d, dt)
            _, u = fluid.fields()
            speeds.append(float(np.abs(fluid.alpha * u[:, 2]).max()))
    print(f"ddt_alpha {ddt_alpha}: largest superficial gas speed per step {['%.3g' % s for s in speeds]} m/s")
    if ddt_alpha:
        assert max(speeds) == pytest.approx(d / dt * (np.pi / 6), rel=0.05)   # the solids' superficial speed
    else:
        assert max(speeds) < 1e-12


def lid_box(path, nprocs):
    """A 2-D-like box with a 0.1 m/s inflow on one side wall and an outlet on top; the
    pressure solved to 1e-10 absolute at every corrector."""
    return box_case(path, lo=(0, 0, 0), hi=(0.04, 0.01, 0.04), cells=(16, 1, 16),
                    gravity=(0, 0, -9.81), dt=5e-3, nprocs=nprocs, rel_tol=0.0,
                    boundaries={"xlo": ("inlet", (0.1, 0, 0)), "xhi": "wall", "ylo": "slip",
                                "yhi": "slip", "zlo": "wall", "zhi": "outlet"}, **WATER)


def test_serial_and_two_ranks_agree(tmp_path):
    """Same case with particles in it, serial and with mpirun -np 2 (method simple)."""
    rng = np.random.default_rng(10007)
    x = rng.uniform((0.002, 0.001, 0.002), (0.038, 0.009, 0.038), (200, 3))
    v = rng.normal(0, 0.05, (200, 3))
    results = []
    for nprocs in (1, 2):
        with FluidSolver(lid_box(tmp_path / f"np{nprocs}", nprocs), nprocs=nprocs,
                         drag="difelice") as fluid:
            for _ in range(20):
                force = fluid.couple(x, v, 1e-3, 5e-3)
            p, u = fluid.fields()
            order = np.lexsort(np.round(fluid.cell_centres, 9).T)  # same order for both
            results.append((force, p[order], u[order], fluid.rank_cells))
            written = fluid.write()
        # the decomposed run's written time is reconstructed into the case, as a serial run leaves it
        assert (tmp_path / f"np{nprocs}" / f"{written:g}" / "U").is_file()
    (f1, p1, u1, _), (f2, p2, u2, ranks) = results
    assert len(ranks) == 2 and min(ranks) > 0
    u_scale, p_scale = np.abs(u1).max(), np.ptp(p1)
    print(f"max |dU| / max|U| = {np.abs(u1 - u2).max() / u_scale:.2e}, "
          f"max |dp| / range p = {np.abs(p1 - p2).max() / p_scale:.2e}, "
          f"max |dF| / max|F| = {np.abs(f1 - f2).max() / np.abs(f1).max():.2e}")
    # Solver tolerances 1e-10 (p) and 1e-10 (U) absolute: agree to 1e-6 relative.
    assert np.abs(u1 - u2).max() <= 1e-6 * u_scale
    assert np.abs(p1 - p2).max() <= 1e-6 * p_scale
    assert np.abs(f1 - f2).max() <= 1e-6 * np.abs(f1).max()


@pytest.mark.parametrize("nprocs", [1, 2])
def test_locate_finds_the_cell_of_every_point_whatever_their_order_and_number(tmp_path, nprocs):
    """LOCATE guesses each point's cell (its cell at the request before, then the cell of the
    point before it) and tests the guess, else OpenFOAM's tree search: in a first request (no
    guesses), the same points shuffled (every guess stale), points added and removed (an
    insertion, a deletion), each point gets the cell that holds it (its centre within half a
    cell on each axis), serially and on two fluid ranks."""
    rng = np.random.default_rng(7)
    lo, hi = np.array([0.0, 0.0, 0.0]), np.array([0.04, 0.01, 0.04])
    half = (hi - lo) / np.array([16, 1, 16]) / 2                    # lid_box's cells
    inside = lambda n: rng.uniform(lo + 1e-4, hi - 1e-4, (n, 3))
    x = inside(500)
    x = x[np.argsort(x[:, 2])]                                      # in space, as LIGGGHTS keeps atoms
    with FluidSolver(lid_box(tmp_path / "case", nprocs), nprocs=nprocs) as fluid:
        for pts in (x, x[rng.permutation(len(x))], np.r_[x[100:], inside(300)], x[:50], x):
            cell = fluid.locate(pts)[0]
            assert np.all(np.abs(pts - fluid.cell_centres[cell]) <= half * (1 + 1e-9))


def test_a_rank_without_particles_does_not_hang_the_others(tmp_path):
    """The lid box split in z (1 x 1 x 2) with every particle in the lower part: the upper rank
    finds none (it used to leave the lower one waiting at the first locate for the tet base
    points findCell synchronises across processor faces). Forces as serially, to 1e-6."""
    from foamlib import FoamFile

    rng = np.random.default_rng(10009)
    x = rng.uniform((0.002, 0.001, 0.002), (0.038, 0.009, 0.015), (100, 3))
    v = rng.normal(0, 0.05, (100, 3))
    forces = []
    for nprocs in (1, 2):
        case = lid_box(tmp_path / f"np{nprocs}", nprocs)
        FoamFile(case / "system" / "decomposeParDict")["coeffs"] = {"n": [1, 1, nprocs]}
        with FluidSolver(case, nprocs=nprocs, drag="difelice", timeout=60) as fluid:
            for _ in range(5):
                force = fluid.couple(x, v, 1e-3, 5e-3)
            forces.append(force)
    assert np.abs(forces[1] - forces[0]).max() <= 1e-6 * np.abs(forces[0]).max()


def test_diverging_run_raises_with_the_solver_message(tmp_path):
    """Inflow of 50 m/s through 1 mm cells with a 1 s step: the run blows up; the host
    gets FluidError with the log's end and goes on (it can start another solver)."""
    case = box_case(tmp_path / "bad", lo=(0, 0, 0), hi=(0.01, 0.001, 0.01), cells=(10, 1, 10),
                    dt=1.0, max_speed=100.0, n_correctors=1,
                    boundaries={"xlo": ("inlet", (50, 0, 0)), "xhi": "outlet", "ylo": "slip",
                                "yhi": "slip", "zlo": "wall", "zhi": "wall"}, **WATER)
    with pytest.raises(FluidError, match="diverged") as err:
        with FluidSolver(case) as fluid:
            for _ in range(50):
                fluid.advance(1.0)
    assert "log.collheatFoam" in str(err.value)
    with FluidSolver(lid_box(tmp_path / "after", 1)) as fluid:
        assert fluid.advance(5e-3) == pytest.approx(5e-3)


@pytest.mark.parametrize("shear", [0.0, 0.04])
def test_a_diverged_run_on_a_strongly_non_orthogonal_mesh_names_it(tmp_path, shear):
    """The same blow-up on the box whose top face is shifted 40 mm over its 10 mm height
    (non-orthogonality 76 deg everywhere, checkMesh): the message names the mesh's
    non-orthogonality and the case's non-orthogonal correctors (0) as a likely cause; on the
    straight box it does not."""
    case = box_case(tmp_path / "bad", lo=(0, 0, 0), hi=(0.01, 0.001, 0.01), cells=(10, 1, 10),
                    dt=1.0, max_speed=100.0, n_correctors=1,
                    boundaries={"xlo": ("inlet", (50, 0, 0)), "xhi": "outlet", "ylo": "slip",
                                "yhi": "slip", "zlo": "wall", "zhi": "wall"}, **WATER)
    mesh = case / "system" / "blockMeshDict"
    top = "(0.0 0.0 0.01) (0.01 0.0 0.01) (0.01 0.001 0.01) (0.0 0.001 0.01)"
    assert top in mesh.read_text()
    mesh.write_text(mesh.read_text().replace(top, f"({shear} 0.0 0.01) ({shear + 0.01} 0.0 0.01) "
                                                  f"({shear + 0.01} 0.001 0.01) ({shear} 0.001 0.01)"))
    with pytest.raises(FluidError, match="diverged") as err:
        with FluidSolver(case) as fluid:
            for _ in range(50):
                fluid.advance(1.0)
    named = "the mesh is strongly non-orthogonal, up to 76.0 deg (checkMesh: 180 faces above 70 deg), with 0 " \
            "non-orthogonal correctors" in str(err.value)
    assert named == (shear > 0), str(err.value)[:600]


def test_an_advance_left_to_run_gives_the_same_fluid_and_waits_at_the_next_use(tmp_path):
    """lid_box with 200 moving particles, 10 couplings: each advance sent with wait=False (the
    host free while the solver steps, as beside the DEM's chunk) against waiting for each. The
    forces, p and U equal to the last bit; the fluid time and the next request take the answer
    first."""
    rng = np.random.default_rng(10011)
    x0 = rng.uniform((0.002, 0.001, 0.002), (0.038, 0.009, 0.038), (200, 3))
    v = rng.normal(0, 0.05, (200, 3))
    results = []
    for wait in (True, False):
        with FluidSolver(lid_box(tmp_path / f"wait{wait}", 1), drag="difelice") as fluid:
            for k in range(10):
                x = np.clip(x0 + 2e-3 * k * v, 1e-4, (0.0399, 0.0099, 0.0399))
                force = fluid.particle_forces(x, v, 1e-3)
                assert fluid.advance(5e-3, wait=wait) == (pytest.approx(5e-3 * (k + 1)) if wait else None)
            assert fluid.time == pytest.approx(0.05)
            results.append((force, *fluid.fields()))
    for waited, overlapped in zip(*results):
        assert np.array_equal(waited, overlapped)


def test_a_failed_advance_left_to_run_raises_at_the_next_use(tmp_path):
    """The diverging case of the test above with every advance sent with wait=False: the
    failure is raised (FluidError naming the divergence) by the next request, not lost."""
    case = box_case(tmp_path / "bad", lo=(0, 0, 0), hi=(0.01, 0.001, 0.01), cells=(10, 1, 10),
                    dt=1.0, max_speed=100.0, n_correctors=1,
                    boundaries={"xlo": ("inlet", (50, 0, 0)), "xhi": "outlet", "ylo": "slip",
                                "yhi": "slip", "zlo": "wall", "zhi": "wall"}, **WATER)
    with pytest.raises(FluidError, match="diverged"):
        with FluidSolver(case) as fluid:
            for _ in range(50):
                assert fluid.advance(1.0, wait=False) is None


@pytest.mark.parametrize("nprocs", [1, 2])
def test_fluid_restarted_from_its_saved_state_continues_bit_for_bit(tmp_path, nprocs):
    """lid_box with 200 particles moving under it: 10 couplings, ``save`` (every field with 17
    digits, the time folder moved out of the case), 10 more; a second solver started from the
    saved state does the same 10: forces on the particles, p and U equal to the last bit, on
    one rank and decomposed on two (the fraction of the saved time is the old one of the first
    step: without it, ddt(alpha) of that step was lost)."""
    rng = np.random.default_rng(1)
    x0 = rng.uniform((0.002, 0.001, 0.002), (0.038, 0.009, 0.038), (200, 3))
    v = rng.normal(0, 0.05, (200, 3))

    def moved(k):                      # the particles at coupling k [m]
        return x0 + 0.0005 * np.sin(k + np.arange(200))[:, None]

    def last_ten(fluid):
        for k in range(10, 20):
            force = fluid.couple(moved(k), v, 1e-3, 5e-3)
        return (force, *fluid.fields())

    with FluidSolver(lid_box(tmp_path / "a", nprocs), nprocs=nprocs, drag="difelice") as fluid:
        for k in range(10):
            fluid.couple(moved(k), v, 1e-3, 5e-3)
        assert fluid.save(tmp_path / "saved") == pytest.approx(0.05)
        whole = last_ten(fluid)
    with FluidSolver(lid_box(tmp_path / "b", nprocs), nprocs=nprocs, drag="difelice",
                     restart=tmp_path / "saved") as fluid:
        assert fluid.time == pytest.approx(0.05)
        restarted = last_ten(fluid)
    for a, b, name in zip(whole, restarted, ("force", "p", "U")):
        assert np.array_equal(a, b), f"{name}: max difference {np.abs(a - b).max():.3g}"
    assert np.abs(whole[2]).max() > 0.05           # a flow, not a fluid at rest


MEAN_SUP = """FoamFile { version 2.0; format ascii; class dictionary; object fvOptions; }
momentumSource
{
    type            meanSupVelocityForce;
    active          yes;
    meanSupVelocityForceCoeffs
    {
        selectionMode   all;
        fields          (U);
        Ubar            (1 0 0);
        relaxation      0.9;
        twoPhase        false;
        coupled         true;
        voidfractionField "voidfraction";
    }
}
"""

FLOW_RATE = {"type": "surfaceFieldValue", "libs": ["libfieldFunctionObjects.so"], "writeControl": "timeStep",
             "writeInterval": 1, "log": False, "writeFields": False, "regionType": "patch", "name": "xlo",
             "operation": "sum", "fields": ["alphaPhi"]}


def periodic_channel(path):
    """A duct 0.4 x 0.1 x 0.1 m, periodic along x (cyclic xlo/xhi), walls around, gas of
    10 kg/m^3; CFDEM's meanSupVelocityForce driving its superficial mean to 1 m/s (as
    CFDEM's periodicChannel); a surfaceFieldValue of the superficial flux through xlo."""
    from foamlib import FoamFile

    case = box_case(path, lo=(0, 0, 0), hi=(0.4, 0.1, 0.1), cells=(8, 4, 4), boundaries=WALLS, rho=10.0,
                    nu=1.5e-5, gravity=(0, 0, 0), dt=1e-3, rel_tol=0.0)
    mesh = FoamFile(case / "system" / "blockMeshDict")
    mesh["boundary"] = [(name, dict(entry, type="cyclic", neighbourPatch={"xlo": "xhi", "xhi": "xlo"}[name])
                         if name in ("xlo", "xhi") else entry) for name, entry in mesh["boundary"]]
    for field in (case / "0").iterdir():
        f = FoamFile(field)
        for name in ("xlo", "xhi"):
            f["boundaryField"][name] = {"type": "cyclic"}
    (case / "system" / "fvOptions").write_text(MEAN_SUP)
    FoamFile(case / "system" / "controlDict")["functions"] = {"flowRate": FLOW_RATE}
    return case


def test_periodic_channel_driven_by_cfdems_mean_velocity_force(tmp_path):
    """CFDEM's periodicChannel drives its flow with meanSupVelocityForce (CFDEM's own; v1912
    lacks it, and v1912's meanVelocityForce misjudges collheatFoam's response: the tutorial
    driven to 10 m/s swung to 11.9 m/s and was at 11.25 m/s at its 10th step). The host's
    copy runs it as collheatMeanVelocityForce: with 300 resting particles of 8 mm in half the
    duct the superficial mean velocity is 1 m/s within 1e-4 after 30 steps, the flux through
    the periodic face is that
    mean times the section (the case's own function object, which the host-driven solver now
    executes at every step), and no gas crosses the walls."""
    from foamlib import FoamFile

    from pyhost.engines.fluid_case import adopt_mean_velocity_force

    case = periodic_channel(tmp_path / "channel")
    assert adopt_mean_velocity_force(case) == ["momentumSource (meanSupVelocityForce)"]
    rng = np.random.default_rng(7)
    x = rng.uniform((0.01, 0.01, 0.01), (0.2, 0.09, 0.09), (300, 3))     # one half of the duct
    with FluidSolver(case, drag="difelice") as fluid:
        for _ in range(30):
            fluid.couple(x, np.zeros((300, 3)), 8e-3, 1e-3)
        t = fluid.write()
        volumes = fluid.cell_volumes
    alpha = np.asarray(FoamFile(case / f"{t:g}" / "alpha")["internalField"])
    u = np.asarray(FoamFile(case / f"{t:g}" / "U")["internalField"])
    assert alpha.min() < 0.99                            # the particles are in the flow
    superficial = float(np.sum(alpha * u[:, 0] * volumes) / volumes.sum())
    interstitial = float(np.sum(u[:, 0] * volumes) / volumes.sum())
    print(f"superficial mean {superficial:.6f} m/s, interstitial {interstitial:.6f} m/s")
    assert superficial == pytest.approx(1.0, abs=1e-4)
    assert interstitial > superficial + 1e-3             # the superficial mean is the one driven
    rows = np.loadtxt(next((case / "postProcessing" / "flowRate").rglob("surfaceFieldValue.dat")), ndmin=2)
    assert len(rows) >= 30                               # a row at every step
    assert abs(rows[-1, 1]) == pytest.approx(superficial * 0.1 * 0.1, rel=2e-2)
