"""LIGGGHTS bridge on the real engine: two 2 mm glass-like spheres meeting head-on."""
import math
from pathlib import Path

import numpy as np
import pytest

from pyhost.engines.liggghts import Liggghts, LiggghtsError, granular_box

pytestmark = pytest.mark.engines

R, RHO, E, NU = 1e-3, 2500.0, 5e6, 0.3          # m, kg/m^3, Pa, -
K, C = 1.0, 800.0                               # W/m/K, J/kg/K
V, DT = 1.0, 1e-6                               # m/s each (head-on), s


def two_spheres(workdir) -> Liggghts:
    lg = Liggghts(workdir)
    lg.commands(granular_box((-0.01,) * 3, (0.01,) * 3, youngs=E, poisson=NU, restitution=1.0,
                             friction=0.5, skin=R / 2, dt=DT))
    lg.commands(f"""
        fix m5 all property/global thermalConductivity peratomtype {K}
        fix m6 all property/global thermalCapacity peratomtype {C}
        create_atoms 1 single {-1.5 * R} 0 0 units box
        create_atoms 1 single {1.5 * R} 0 0 units box
        set atom 1 diameter {2 * R} density {RHO} vx {V}
        set atom 2 diameter {2 * R} density {RHO} vx {-V}
        fix heat all heat/gran initial_temperature 300
        fix integrate all nve/sphere
    """)
    lg.add_pair_contacts()
    return lg


def hertz_contact_time(v_rel: float, wall: bool = False) -> float:
    """Duration (s) of an elastic Hertz impact of two equal spheres, or of one sphere on a
    wall of the same material (Johnson 1985, eq. 11.24)."""
    m_eff = RHO * 4 / 3 * math.pi * R**3 * (1.0 if wall else 0.5)
    r_eff = R if wall else R / 2
    e_eff = E / (2 * (1 - NU**2))
    return 2.8683 * (m_eff**2 / (r_eff * e_eff**2 * v_rel)) ** 0.2


def test_contact_list_shows_the_pair_for_the_hertz_duration(tmp_path):
    with two_spheres(tmp_path) as lg:
        lg.run(0)
        steps_in_contact, pairs = 0, set()
        for _ in range(1500):
            lg.run(1)
            c = lg.pair_contacts()
            steps_in_contact += len(c)
            pairs |= {tuple(sorted(p)) for p in zip(c.i, c.j)}
            if len(c):
                assert np.allclose(c.vi - c.vj, lg.atom("v")[0] - lg.atom("v")[1])
        expected = hertz_contact_time(2 * V) / DT
        print(f"pair contact: {steps_in_contact} steps, Hertz {expected:.1f}")
        assert pairs == {(1, 2)}
        # Hertz with e = 1; the count is a whole number of steps: 1 % plus one step.
        assert abs(steps_in_contact - expected) <= 0.01 * expected + 1
        # The spheres rebound with their speed (e = 1): momentum and energy kept to 1e-3.
        assert np.allclose(lg.atom("v")[:, 0], [-V, V], rtol=1e-3)


STL_PLANE = """solid plane
facet normal 0 0 1
outer loop
vertex -0.01 -0.01 {z}
vertex 0.01 -0.01 {z}
vertex 0.01 0.01 {z}
endloop
endfacet
facet normal 0 0 1
outer loop
vertex -0.01 -0.01 {z}
vertex 0.01 0.01 {z}
vertex -0.01 0.01 {z}
endloop
endfacet
endsolid plane
"""


@pytest.mark.parametrize("wall", ["mesh", "plane"])
def test_wall_contact_list_shows_the_sphere_for_the_hertz_duration(tmp_path, wall):
    """One sphere (1 m/s normal, 0.1 m/s tangential) onto a plane at z = -5 mm, as a mesh
    wall (compute wall/gran/local) and as a primitive plane (geometry)."""
    z_wall = -0.005
    with Liggghts(tmp_path) as lg:
        lg.commands(granular_box((-0.01,) * 3, (0.01,) * 3, youngs=E, poisson=NU,
                                 restitution=1.0, friction=0.5, skin=R / 2, dt=DT))
        if wall == "mesh":
            (tmp_path / "plane.stl").write_text(STL_PLANE.format(z=z_wall))
            lg.command(f"fix cad all mesh/surface file {tmp_path / 'plane.stl'} type 1")
            lg.command("fix wall all wall/gran model hertz tangential history mesh "
                       "n_meshes 1 meshes cad")
        else:
            lg.command("fix wall all wall/gran model hertz tangential history primitive "
                       f"type 1 zplane {z_wall}")
        lg.commands(f"""
            create_atoms 1 single 0.001 0.002 {z_wall + 1.5 * R} units box
            set atom 1 diameter {2 * R} density {RHO} vx 0.1 vz {-V}
            fix integrate all nve/sphere
        """)
        if wall == "mesh":
            lg.add_wall_contacts()
        lg.run(0)
        steps_in_contact = 0
        for _ in range(1500):
            lg.run(1)
            c = lg.wall_contacts() if wall == "mesh" else lg.plane_contacts(2, z_wall)
            steps_in_contact += len(c)
            if len(c):
                assert c.i.tolist() == [1] and c.j.tolist() == [0]
                assert np.allclose(c.vi - c.vj, lg.atom("v"))
                x = lg.atom("x")
                assert c.delta[0] == pytest.approx(R - (x[0, 2] - z_wall), rel=1e-6, abs=1e-12)
                lens = np.pi * (2 * R * c.delta[0] - c.delta[0] ** 2)   # the cut circle
                assert c.area[0] == pytest.approx(lens, rel=1e-6, abs=1e-18)
        expected = hertz_contact_time(V, wall=True) / DT
        print(f"{wall} wall contact: {steps_in_contact} steps, Hertz {expected:.1f}")
        assert abs(steps_in_contact - expected) <= 0.01 * expected + 1
        assert lg.atom("v")[0, 2] == pytest.approx(V, rel=1e-3)


def test_temperatures_written_from_python_drive_the_next_steps(tmp_path):
    with two_spheres(tmp_path) as lg:
        lg.run(0)                 # values written before the first run are reset by it
        lg.temperature()[:] = [400.0, 300.0]
        m = RHO * 4 / 3 * math.pi * R**3
        h_sum = 0.0               # sum over steps of h * (T1 - T2) * dt, from the contact list
        for _ in range(1500):
            t1, t2 = lg.temperature()
            lg.run(1)
            c = lg.pair_contacts()
            if len(c):
                # fix heat/gran: h = 4 k_i k_j / (k_i + k_j) sqrt(A) = 2 k sqrt(A), with A the
                # contact area of the list (the lens of two equal spheres: pi (R delta - delta^2/4))
                lens = math.pi * (R * c.delta[0] - c.delta[0] ** 2 / 4)
                assert c.area[0] == pytest.approx(lens, rel=1e-6)
                h_sum += 2 * K * math.sqrt(c.area[0]) * (t1 - t2) * DT
        t1, t2 = lg.temperature()
        assert t1 + t2 == pytest.approx(700.0, abs=1e-9)     # heat is conserved
        assert 400.0 - t1 > 1e-3                               # and some was conducted
        print(f"heat conducted {(400.0 - t1) * m * C:.4e} J, from the contact list {h_sum:.4e} J")
        assert (400.0 - t1) * m * C == pytest.approx(h_sum, rel=1e-3)


def test_bad_command_raises_with_liggghts_message_and_host_survives(tmp_path):
    with two_spheres(tmp_path) as lg:
        with pytest.raises(LiggghtsError, match='Invalid fix style: "bogus"'):
            lg.command("fix f1 all bogus 1 2 3")
        with pytest.raises(LiggghtsError, match="ERROR"):
            lg.command("pair_coeff 7 7")
        lg.run(10)                 # the instance is unharmed by refused commands and still runs
        assert lg.step == 10


def test_commands_tried_together_fork_once_and_a_bad_one_still_reports_its_own_error(tmp_path, monkeypatch):
    """try_ahead tries a block of commands in one forked copy: the commands that passed there
    run without a fork of their own; the first that failed is tried alone when it comes, and
    raises LIGGGHTS' own message; the instance still runs."""
    import os
    forks = []
    real_fork = os.fork
    monkeypatch.setattr(os, "fork", lambda: forks.append(1) or real_fork())
    with two_spheres(tmp_path) as lg:
        good = ["variable a equal 1.0", "variable b equal v_a*2", "fix g all gravity 9.81 vector 0 0 -1"]
        forks.clear()
        lg.try_ahead(good)
        for line in good:
            lg.command(line)
        assert len(forks) == 1                     # one copy for the three
        block = ["variable c equal 3.0", "fix f1 all bogus 1 2 3", "variable d equal 4.0"]
        forks.clear()
        lg.try_ahead(block)
        lg.command(block[0])                       # passed in the copy: no fork of its own
        assert len(forks) == 1
        with pytest.raises(LiggghtsError, match='Invalid fix style: "bogus"'):
            lg.command(block[1])                   # tried alone: LIGGGHTS' message
        assert len(forks) == 2
        lg.command(block[2])                       # after the failure, each alone again
        assert len(forks) == 3
        assert lg.variable("b") == 2.0 and lg.variable("d") == 4.0
        lg.run(10)
        assert lg.step == 10


def test_a_command_run_before_is_not_tried_again_and_a_failing_repeat_still_returns(tmp_path, monkeypatch):
    """A command run before without error (a CFDEM case's 'set ... Temp' at every coupling
    step) runs without a forked trial, and so does the set-up of the next run when only such
    repeats came since the last: 2 forks for the first round, 0 for each later one (before: 2
    each). A repeat that fails now (an unfix of a fix gone) raises LIGGGHTS' own message through
    the helper, as a chunk that fails: the process survives, its atoms stay readable (the run's
    summary), and the instance runs nothing more."""
    import os
    forks = []
    real_fork = os.fork
    monkeypatch.setattr(os, "fork", lambda: forks.append(1) or real_fork())
    with two_spheres(tmp_path) as lg:
        lg.run(1)
        counts = []
        for _ in range(3):
            forks.clear()
            lg.command("set group all vx 0.5")
            lg.run(5)
            counts.append(len(forks))
        assert counts == [2, 0, 0] and lg.step == 16
        assert np.all(lg.atom("v")[:, 0] == 0.5)           # the repeat ran: each round starts at 0.5 m/s
        lg.command("fix g all gravity 9.81 vector 0 0 -1")
        lg.command("unfix g")
        forks.clear()
        with pytest.raises(LiggghtsError, match="Could not find fix ID to delete"):
            lg.command("unfix g")                           # a known line failing now: no fork, the message
        assert forks == [] and lg.atom("x").shape == (2, 3)
        with pytest.raises(LiggghtsError, match="runs nothing more"):
            lg.run(1)                                       # (as after a chunk that failed)


def test_a_crash_in_the_trial_copy_is_reported_as_a_crash(tmp_path):
    """A trial copy that dies of a signal (a fault, no ERROR line) is said to have crashed,
    naming the signal, where it used to be "LIGGGHTS refused ...: no message". The instance
    is unharmed and still runs."""
    import ctypes
    with two_spheres(tmp_path) as lg:
        with pytest.raises(LiggghtsError, match=r"LIGGGHTS crashed on 'x' \(signal SIGSEGV, no error message"):
            lg._tried(lambda: ctypes.string_at(0), "x")
        lg.run(10)
        assert lg.step == 10


def test_the_crashed_copy_prints_no_python_dump():
    """The crash test above, run by pytest as the default test run runs it (faulthandler on):
    the copy's fault printed "Fatal Python error: Segmentation fault" and 20 lines of Python
    stack in the suite's output; the copy no longer dumps (the parent reports the crash)."""
    import subprocess
    import sys
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        f"{__file__}::test_a_crash_in_the_trial_copy_is_reported_as_a_crash"],
                       capture_output=True, text=True, cwd=Path(__file__).resolve().parents[2], timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    assert "1 passed" in r.stdout
    assert "Fatal Python error" not in r.stdout + r.stderr, r.stdout + r.stderr


def test_error_in_a_later_chunk_returns_with_liggghts_message(tmp_path):
    """Chunks after the first are not tried in a forked copy: LIGGGHTS' error (here Error::one
    of a 'fix print' reaching an undefined variable at step 20) returns from the run as
    LiggghtsFailed, with its message and the step, instead of ending the process. The atoms
    stay readable (for the summary); the instance refuses to run on."""
    from pyhost.engines.liggghts import LiggghtsFailed
    with two_spheres(tmp_path) as lg:
        lg.command('fix p all print 20 "$${nothere}" screen no')
        lg.run(1)
        with pytest.raises(LiggghtsFailed, match="at step 20: ERROR: Substitution for illegal variable"):
            lg.run(30)
        assert lg.atom("x").shape == (2, 3) and np.all(np.isfinite(lg.atom("x")))
        with pytest.raises(LiggghtsError, match="runs nothing more"):
            lg.run(1)


def test_short_chunks_on_a_static_mesh_step_as_one_run(tmp_path):
    """A pour onto an STL floor run as 1200 chunks of 5 steps (``run 5 pre no post no``, with
    the mesh's triangle bins kept between chunks: plugins/liggghts/run_chunks.cpp) and as one
    run of 6000 steps, the spheres landed: the same positions, bit for bit. LIGGGHTS itself would rebuild each
    triangle's bins at every chunk (chute_wear: 19.4 s in 1,000 chunks against 12.5 s)."""
    from test_contact_events import FLOOR, pour_on_floor
    (tmp_path / "floor.stl").write_text(FLOOR)
    positions, kept = [], []
    for chunks in (1200, 1):
        work = tmp_path / f"chunks{chunks}"
        with Liggghts(work) as lg:
            lg.commands(granular_box((-0.01,) * 3, (0.01,) * 3, youngs=5e6, poisson=0.3, restitution=0.5,
                                     friction=0.5, skin=5e-4, dt=1e-5))
            lg.commands(pour_on_floor(tmp_path / "floor.stl"))
            lg.run(1)
            for _ in range(chunks):
                lg.run(6000 // chunks)
            kept.append(lg.helper.collheat_keep_mesh_bins(lg.ptr))
            order = np.argsort(lg.atom("id"))
            positions.append(lg.atom("x")[order].copy())
    assert kept == [1, 1]                               # the mesh's list was told to keep its bins
    assert len(positions[0]) == 60 and positions[0][:, 2].min() < -0.0089   # (landed on the floor at z = -0.01)
    assert np.array_equal(positions[0], positions[1])
