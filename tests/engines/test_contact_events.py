"""Contact events recorded inside LIGGGHTS at every step (plugins/liggghts/contact_events.cpp,
pyhost.engines.events) on the real engine, against closed forms and LIGGGHTS' own contact list."""
import math

import numpy as np
import pytest

from pyhost.collisions import WALL_BASE
from pyhost.engines.events import BEGIN, END, ContactEvents
from pyhost.engines.liggghts import Liggghts, granular_box

pytestmark = pytest.mark.engines

R, RHO, E, NU = 1e-3, 2500.0, 5e6, 0.3          # m, kg/m^3, Pa, -
DT = 1e-6                                       # s


def hertz_contact_time(v_rel: float, wall: bool = False) -> float:
    """Elastic Hertz impact duration [s] of two equal spheres (or one on a wall of the same
    material), Johnson (1985) eq. 11.24."""
    m_eff = RHO * 4 / 3 * math.pi * R**3 * (1.0 if wall else 0.5)
    r_eff = R if wall else R / 2
    e_eff = E / (2 * (1 - NU**2))
    return 2.8683 * (m_eff**2 / (r_eff * e_eff**2 * v_rel)) ** 0.2


def box(tmp_path, lo=(-0.01,) * 3, hi=(0.01,) * 3, dt=DT) -> Liggghts:
    lg = Liggghts(tmp_path)
    lg.commands(granular_box(lo, hi, youngs=E, poisson=NU, restitution=1.0, friction=0.5, skin=R / 2, dt=dt))
    return lg


def head_on(lg, V):
    """Two spheres 3R apart on the x axis, closing in at V each [m/s]."""
    lg.commands(f"""
        create_atoms 1 single {-1.5 * R} 0 0 units box
        create_atoms 1 single {1.5 * R} 0 0 units box
        set atom 1 diameter {2 * R} density {RHO} vx {V}
        set atom 2 diameter {2 * R} density {RHO} vx {-V}
        fix integrate all nve/sphere
    """)


def test_a_head_on_pair_gives_one_begin_at_its_impact_speed_and_one_end_after_the_hertz_time(tmp_path):
    V = 1.0                                     # m/s each
    with box(tmp_path) as lg:
        head_on(lg, V)
        ev = ContactEvents(lg)
        lg.run(1500)
        got = ev.take()
    begin, end = got[got["kind"] == BEGIN], got[got["kind"] == END]
    assert len(begin) == 1 and len(end) == 1
    b = begin[0]
    assert (b["i"], b["j"], bool(b["wall"])) == (1, 2, False)
    # before the first overlap no force has acted: vn is the approach speed 2V to round-off
    assert b["vn"] == pytest.approx(2 * V, rel=1e-12)
    assert np.allclose(b["n"], [-1.0, 0.0, 0.0], atol=1e-12)        # from 2 (at +x) to 1
    # they first overlap after (3R - 2R)/(2V) = R/(2V) = 500 steps
    assert b["step"] == math.floor(R / (2 * V) / DT) + 1
    expected = hertz_contact_time(2 * V) / DT
    print(f"duration {end[0]['duration']} steps, Hertz {expected:.1f}")
    assert abs(end[0]["duration"] - expected) <= 0.01 * expected + 1


def test_a_sphere_dropped_on_a_plane_begins_at_the_free_fall_speed(tmp_path):
    h = 0.005                                   # m of free fall to the plane
    with box(tmp_path, dt=1e-6) as lg:
        lg.commands(f"""
            fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.01
            fix gravi all gravity 9.81 vector 0 0 -1
            create_atoms 1 single 0 0 {-0.01 + R + h} units box
            set atom 1 diameter {2 * R} density {RHO}
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        assert not ev.primitives(["gravi"], [WALL_BASE + 0])      # not a primitive wall: refused
        assert ev.primitives(["floor"], [WALL_BASE + 0])
        lg.run(40000)
        got = ev.take()
    begin = got[got["kind"] == BEGIN]
    assert len(begin) >= 1 and bool(begin[0]["wall"]) and begin[0]["j"] == WALL_BASE
    v = math.sqrt(2 * 9.81 * h)
    print(f"vn {begin[0]['vn']:.6f} m/s, sqrt(2 g h) {v:.6f}")
    # the step's discrete fall: within g dt of the exact speed and of the overlap's depth
    assert begin[0]["vn"] == pytest.approx(v, rel=1e-3)
    assert np.allclose(begin[0]["n"], [0, 0, 1])


def test_a_plane_given_after_the_recorder_sees_a_falling_sphere_and_not_a_resting_one(tmp_path):
    """A plane whose fix wall/gran comes after the recorder's fix (a script adding a wall
    between runs): at the run's set-up the recorder runs before the wall has listed its nearby
    particles, so it lists them itself. A sphere already touching the plane when it is given
    is in contact, not colliding; one falling onto it begins at the free-fall speed."""
    h = 0.002
    with box(tmp_path, dt=1e-6) as lg:
        lg.commands(f"""
            fix gravi all gravity 9.81 vector 0 0 -1
            create_atoms 1 single -0.004 0 {R * 0.999} units box
            create_atoms 1 single 0.004 0 {R + h} units box
            set atom * diameter {2 * R} density {RHO}
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        lg.run(1)
        lg.commands("fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0")
        assert ev.primitives(["floor"], [WALL_BASE + 0])
        lg.run(25000)
        got = ev.take()
    begin = got[got["kind"] == BEGIN]
    v = math.sqrt(2 * 9.81 * h)
    assert begin["i"].tolist() == [2], "the resting sphere counted as a collision, or the falling one missed"
    assert begin[0]["vn"] == pytest.approx(v, rel=1e-3)


def test_a_sphere_thrown_at_a_cylinder_wall_begins_at_its_radial_speed(tmp_path):
    """A sphere inside a zcylinder wall (radius 8 mm, axis off the origin), thrown outward along
    x and y at once: it begins touching the cylinder at the step its surface reaches it, with
    the approach speed its velocity's radial part, and the normal from the wall to it pointing
    to the axis."""
    Rc, cx, cy, v = 0.008, 0.001, -0.0005, (0.3, 0.4)
    with box(tmp_path) as lg:
        lg.commands(f"""
            fix tube all wall/gran model hertz tangential history primitive type 1 zcylinder {Rc} {cx} {cy}
            create_atoms 1 single {cx} {cy} 0 units box
            set atom 1 diameter {2 * R} density {RHO} vx {v[0]} vy {v[1]}
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        assert ev.primitives(["tube"], [WALL_BASE + 0])
        lg.run(30000)
        got = ev.take()
    begin = got[got["kind"] == BEGIN]
    assert len(begin) >= 1 and bool(begin[0]["wall"]) and begin[0]["j"] == WALL_BASE
    speed = math.hypot(*v)
    print(f"step {begin[0]['step']}, vn {begin[0]['vn']:.12f} m/s")
    assert begin[0]["step"] == math.floor((Rc - R) / speed / DT) + 1       # free flight from the axis
    assert begin[0]["vn"] == pytest.approx(speed, rel=1e-12)              # radial: the whole velocity
    assert np.allclose(begin[0]["n"], [-v[0] / speed, -v[1] / speed, 0.0], atol=1e-9)


def test_a_wall_of_a_group_meets_only_that_group(tmp_path):
    """A plane whose fix wall/gran acts on group 'held' only: of two spheres moving down onto it
    at 0.5 m/s, the one of that group bounces (one wall contact begins, at its speed), the other
    passes through it as LIGGGHTS lets it (no contact recorded for it)."""
    with box(tmp_path) as lg:
        lg.commands(f"""
            create_atoms 1 single -0.004 0 {2 * R} units box
            create_atoms 1 single 0.004 0 {2 * R} units box
            set atom * diameter {2 * R} density {RHO} vz -0.5
            group held id 1
            fix floor held wall/gran model hertz tangential history primitive type 1 zplane 0.0
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        assert ev.primitives(["floor"], [WALL_BASE + 0])
        lg.run(round(4 * R / 0.5 / DT))
        got = ev.take()
        z = dict(zip(lg.atom("id").astype(int).tolist(), lg.atom("x")[:, 2].tolist()))
    begin = got[got["kind"] == BEGIN]
    assert begin["i"].tolist() == [1] and begin[0]["vn"] == pytest.approx(0.5, rel=1e-12)
    assert z[1] > 0 > z[2]                     # the held one bounced, the other went through


def test_a_ycylinder_reads_its_axis_as_liggghts_does(tmp_path):
    """LIGGGHTS reads ``ycylinder R c1 c2`` with c1 the axis' z and c2 its x (the axes after y,
    cyclically; primitive_wall_definitions.h), not x then z. A sphere on that axis, thrown
    outward in x and z, begins touching the wall at the step free flight gives, at its whole
    speed, the normal pointing back to the axis; pyhost.walls (post, the scene checks) sees
    the same contact there."""
    from pyhost.walls import primitive_overlap

    Rc, c1, c2, v = 0.008, 0.002, -0.001, (0.3, 0.41)         # axis at z = c1, x = c2
    with box(tmp_path) as lg:
        lg.commands(f"""
            fix tube all wall/gran model hertz tangential history primitive type 1 ycylinder {Rc} {c1} {c2}
            create_atoms 1 single {c2} 0 {c1} units box
            set atom 1 diameter {2 * R} density {RHO} vx {v[0]} vz {v[1]}
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        assert ev.primitives(["tube"], [WALL_BASE + 0])
        speed = math.hypot(*v)
        first = math.floor((Rc - R) / speed / DT) + 1
        lg.run(first)
        got = ev.take()
        x = lg.atom("x").copy()
    begin = got[got["kind"] == BEGIN]
    assert len(begin) == 1 and begin[0]["step"] == first
    assert begin[0]["vn"] == pytest.approx(speed, rel=1e-12)
    assert np.allclose(begin[0]["n"], [-v[0] / speed, 0.0, -v[1] / speed], atol=1e-9)
    delta, normal = primitive_overlap(x, np.array([R]), ("ycylinder", (Rc, c1, c2)))
    assert delta[0] > 0 and np.allclose(normal[0], begin[0]["n"], atol=1e-9)


def test_wall_events_follow_the_geometry_step_by_step(tmp_path):
    """200 spheres poured into a zcylinder (radius 8 mm) on a floor plane, beside an xplane: at
    every step the particles that begin and end touching each primitive wall are exactly those
    whose distance to it crosses their radius (LIGGGHTS' own test). The recorder takes each
    wall's geometry and its list of nearby particles (made at each neighbour build) from
    LIGGGHTS' fix wall/gran."""
    Rc, floor, side = 0.008, -0.01, 0.0075
    with box(tmp_path, dt=1e-5) as lg:
        lg.commands(f"""
            fix floor all wall/gran model hertz tangential history primitive type 1 zplane {floor}
            fix side all wall/gran model hertz tangential history primitive type 1 xplane {side}
            fix tube all wall/gran model hertz tangential history primitive type 1 zcylinder {Rc} 0 0
            fix gravi all gravity 9.81 vector 0 0 -1
            region fill cylinder z 0 0 0.006 -0.009 0.005 units box
            fix pts all particletemplate/sphere 15485863 atom_type 1 density constant {RHO} radius constant {R}
            fix pdd all particledistribution/discrete 15485867 1 pts 1.0
            fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0.05 0 -0.3 insert_every once overlapcheck yes all_in yes particles_in_region 200 region fill
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        assert ev.primitives(["floor", "side", "tube"], [WALL_BASE + 0, WALL_BASE + 1, WALL_BASE + 2])
        lg.run(1)
        ev.take()

        def touching():
            ids, x, r = lg.atom("id").astype(int), lg.atom("x"), lg.atom("radius")
            gaps = {0: np.abs(x[:, 2] - floor), 1: np.abs(x[:, 0] - side),
                    2: np.abs(np.hypot(x[:, 0], x[:, 1]) - Rc)}
            return {(int(i), WALL_BASE + w) for w, g in gaps.items() for i in ids[r - g > 0]}

        before = touching()
        begun, ended, met = 0, 0, set()
        for _ in range(3000):
            lg.run(1)
            now = touching()
            got = ev.take()
            walls = got[got["wall"]]
            pairs = lambda kind: {(int(e["i"]), int(e["j"])) for e in walls[walls["kind"] == kind]}
            assert pairs(BEGIN) == now - before
            assert pairs(END) == before - now
            begun += len(now - before)
            ended += len(before - now)
            met |= {j for _, j in now - before}
            before = now
        print(f"{begun} wall contacts begun, {ended} ended, {len(now)} open at the end")
        assert begun > 100 and ended > 10 and met == {WALL_BASE, WALL_BASE + 1, WALL_BASE + 2}


def test_a_sphere_grown_into_a_plane_begins_touching_it(tmp_path):
    """A sphere at rest 1.7 R above a plane (farther than its radius and the skin, R/2, when the
    recorder first lists the particles near each wall), grown by fix adapt at every step until
    it reaches the plane: the contact begins at the step the radius passes the gap. (LIGGGHTS
    builds its lists again, the wall's list of nearby particles among them, as the growth uses
    up the skin.)"""
    gap = 1.7 * R
    with box(tmp_path) as lg:
        lg.commands(f"""
            fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
            create_atoms 1 single 0 0 {gap} units box
            set atom 1 diameter {2 * R} density {RHO}
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        assert ev.primitives(["floor"], [WALL_BASE])
        lg.run(1)
        ev.take()
        lg.commands(f"""
            variable dgrow atom {2 * R}*(1+1e-4*(step-1))
            fix grow all adapt 1 atom diameter v_dgrow
        """)
        steps = []
        for _ in range(8000):
            lg.run(1)
            got = ev.take()
            steps += [int(e["step"]) for e in got[got["kind"] == BEGIN]]
            if steps:
                break
        r, z = float(lg.atom("radius")[0]), float(lg.atom("x")[0, 2])
    assert len(steps) == 1, "the grown sphere's contact with the plane was not recorded"
    print(f"begun at step {steps[0]}: radius {r / R:.5f} R, centre {z / R:.5f} R above the plane")
    assert r > z and r - z < 2e-4 * R          # the first step in contact: the radius just past the gap


def test_heat_gran_flux_histories_equal_liggghts_own_per_contact_flux(tmp_path):
    """With a fix heat/gran (area correction on), the recorder keeps the flux through each new
    pair contact at each of its first steps: the head-on pair's history equals, step by step,
    the heatFlux heat/gran itself summed into atom 1 at that step (its only contact), to
    1e-12; the begin carries the two temperatures of its step."""
    V, window = 0.5, 40
    with box(tmp_path) as lg:
        head_on(lg, V)
        lg.commands(f"""
            fix ym0 all property/global youngsModulusOriginal peratomtype {4 * E}
            fix k all property/global thermalConductivity peratomtype 20.0
            fix c all property/global thermalCapacity peratomtype 500.0
            fix heat all heat/gran initial_temperature 300. area_correction yes
            run 0
            set atom 1 property/atom Temp 400.
        """)
        ev = ContactEvents(lg)
        ev.conduction("heat", window)
        lg.run(1)
        flux = []
        for _ in range(1500):
            lg.run(1)
            q = lg.property_atom("heatFlux")[np.argsort(lg.atom("id"))]
            if q[0] != 0:
                assert q[1] == pytest.approx(-q[0], rel=1e-12)
                flux.append(q[0])                                   # into atom 1 [W]
        got = ev.take()
        i, j, start, filled, history = ev.histories(all=True)
    begin = got[got["kind"] == BEGIN]
    assert len(begin) == 1 and np.allclose(begin[0]["T"], [400.0, 300.0], rtol=0, atol=1e-9)
    assert (i[0], j[0], start[0], filled[0]) == (1, 2, begin[0]["step"], window)
    assert len(flux) > window
    assert np.allclose(history[0], flux[:window], rtol=1e-12, atol=0)


def pile(folder, bottom: float, vz: float, every, count: int) -> Liggghts:
    """A 2 x 2 x 4 cm box with a floor and gravity, spheres of radius 1 mm inserted at ``vz``
    [m/s] into the region from ``bottom`` [m] to the top, ``count`` at a time ``every`` steps
    (or "once"); LIGGGHTS open, nothing run."""
    lg = box(folder, lo=(0, 0, 0), hi=(0.02, 0.02, 0.04), dt=1e-5)
    lg.commands(f"""
        fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
        fix gravi all gravity 9.81 vector 0 0 -1
        region fill block 0.001 0.019 0.001 0.019 {bottom} 0.039 units box
        fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
        fix pdd all particledistribution/discrete 15485867 1 pts 1.0
        fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 {vz} insert_every {every} overlapcheck yes all_in yes particles_in_region {count} region fill
        fix integrate all nve/sphere
    """)
    return lg


def test_events_follow_liggghts_own_contact_list_step_by_step(tmp_path):
    """A pile of 200 spheres settling: at every step, the pairs begun are exactly the pairs
    that compute pair/gran/local lists now and did not list on the step before, and the ended
    ones those it no longer lists."""
    with pile(tmp_path, 0.001, -0.3, "once", 200) as lg:
        lg.add_pair_contacts()
        ev = ContactEvents(lg)
        lg.run(1)
        ev.take()
        key = lambda i, j: (int(min(i, j)), int(max(i, j)))
        c = lg.pair_contacts()
        before = {key(i, j) for i, j in zip(c.i, c.j)}
        begun = ended = 0
        for _ in range(6000):
            lg.run(1)
            c = lg.pair_contacts()
            now = {key(i, j) for i, j in zip(c.i, c.j)}
            got = ev.take()
            pairs = got[~got["wall"]]
            assert {key(e["i"], e["j"]) for e in pairs[pairs["kind"] == BEGIN]} == now - before
            assert {key(e["i"], e["j"]) for e in pairs[pairs["kind"] == END]} == before - now
            begun += len(now - before)
            ended += len(before - now)
            before = now
        print(f"{begun} pair contacts begun, {ended} ended, {len(now)} open at the end")
        assert begun > 200 and ended > 100


def test_events_catch_a_collision_shorter_than_the_sampling_interval(tmp_path):
    """Two fast stiff spheres whose contact lasts 3 steps: sampling LIGGGHTS' contact list
    every 5 steps misses it; the events record its begin and end."""
    V = 2.0
    t_c = hertz_contact_time(2 * V)
    dt = t_c / 3.2                              # about 3 steps in contact
    with box(tmp_path, dt=dt) as lg:
        head_on(lg, V)
        lg.add_pair_contacts()
        ev = ContactEvents(lg)
        lg.run(0)
        start = math.floor(R / (2 * V) / dt) + 1        # first step in contact
        lg.run(start - 1 - (start - 1) % 5 + 5 if (start - 1) % 5 else start - 1)
        samples = []
        while lg.step < start + 20:
            lg.run(5)
            samples.append(len(lg.pair_contacts()))
        got = ev.take()
    begin, end = got[got["kind"] == BEGIN], got[got["kind"] == END]
    print(f"samples every 5 steps saw {sum(samples)} contacts; events: {len(begin)} begin, "
          f"duration {end['duration'].tolist()} steps")
    assert sum(samples) == 0
    assert len(begin) == 1 and len(end) == 1 and 1 <= end[0]["duration"] <= 5
    assert begin[0]["vn"] == pytest.approx(2 * V, rel=1e-12)


FLOOR = """solid floor
facet normal 0 0 1
outer loop
vertex -0.02 -0.02 -0.01
vertex 0.02 -0.02 -0.01
vertex 0.02 0.02 -0.01
endloop
endfacet
facet normal 0 0 1
outer loop
vertex -0.02 -0.02 -0.01
vertex 0.02 0.02 -0.01
vertex -0.02 0.02 -0.01
endloop
endfacet
endsolid floor
"""


def pour_on_floor(stl) -> str:
    """60 spheres of 1 mm radius at rest in the box, falling onto the STL floor at z = -0.01 m."""
    return f"""
        fix gravi all gravity 9.81 vector 0 0 -1
        fix cad all mesh/surface file {stl} type 1
        fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad
        region fill block -0.008 0.008 -0.008 0.008 -0.006 0.009 units box
        fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
        fix pdd all particledistribution/discrete 15485867 1 pts 1.0
        fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 0 insert_every once overlapcheck yes all_in yes particles_in_region 60 region fill
        fix integrate all nve/sphere
    """


@pytest.mark.parametrize("recorder_first", [False, True])
def test_mesh_wall_events_follow_liggghts_own_wall_contact_list(tmp_path, recorder_first):
    """Spheres poured onto an STL floor (two triangles): a sphere meets it at the free-fall
    speed, and at every step the particles that begin and end touching the mesh are exactly
    those compute wall/gran/local gains and loses (a particle on both triangles is one contact).
    Both ways the recorder finds them: from fix wall/gran's own mesh contact history (the wall
    fix before the recorder's) and by its own sphere-triangle test (the wall fix after it)."""
    (tmp_path / "floor.stl").write_text(FLOOR)
    with box(tmp_path, dt=1e-5) as lg:
        ev = ContactEvents(lg) if recorder_first else None
        lg.commands(pour_on_floor(tmp_path / "floor.stl"))
        lg.add_wall_contacts()
        ev = ev or ContactEvents(lg)
        lg.run(1)
        assert ev.meshes(["cad"], [WALL_BASE + 3])
        lg.run(1)
        assert ev.meshes_by_history == (0 if recorder_first else 1)
        ev.take()
        z0 = {int(i): z for i, z in zip(lg.atom("id"), lg.atom("x")[:, 2])}
        # compute wall/gran/local 'vel id contactArea delta': ids are columns 6-8 (mesh, triangle,
        # atom: LIGGGHTS' order, ENGINES.md); a particle on both triangles is listed twice
        touching = lambda: set(lg.local_array("walls")[:, 8].astype(int).tolist())
        before = touching()
        begun = 0
        first = None
        for _ in range(4000):
            lg.run(1)
            now = touching()
            got = ev.take()
            walls = got[got["wall"]]
            assert set(walls["j"].tolist()) <= {WALL_BASE + 3}
            assert set(walls[walls["kind"] == BEGIN]["i"].tolist()) == now - before
            assert set(walls[walls["kind"] == END]["i"].tolist()) == before - now
            if first is None and len(walls[walls["kind"] == BEGIN]):
                first = walls[walls["kind"] == BEGIN][0]
            begun += len(now - before)
            before = now
    h = z0[int(first["i"])] - (-0.01 + R)             # its fall from rest to touch
    print(f"{begun} mesh contacts begun; first at vn {first['vn']:.5f} m/s, sqrt(2 g h) {math.sqrt(2 * 9.81 * h):.5f}")
    assert begun >= 10
    assert first["vn"] == pytest.approx(math.sqrt(2 * 9.81 * h), rel=1e-2)
    assert np.allclose(first["n"], [0, 0, 1], atol=1e-9)


def test_a_moving_mesh_meets_a_particle_at_its_own_speed(tmp_path):
    """An STL plate moved up at 0.2 m/s by fix move/mesh into a sphere at rest (no gravity):
    the contact begins with the relative approach speed, the plate's 0.2 m/s (to 1e-9), not
    the particle's 0; the normal points from the plate up to the sphere."""
    (tmp_path / "floor.stl").write_text(FLOOR)
    V = 0.2
    with box(tmp_path, dt=1e-6) as lg:
        lg.commands(f"""
            fix cad all mesh/surface file {tmp_path / 'floor.stl'} type 1
            fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad
            fix lift all move/mesh mesh cad linear 0. 0. {V}
            create_atoms 1 single 0.001 -0.002 {-0.01 + R + 0.0005} units box
            set atom 1 diameter {2 * R} density {RHO}
            fix integrate all nve/sphere
        """)
        ev = ContactEvents(lg)
        lg.run(1)
        assert ev.meshes(["cad"], [WALL_BASE + 0])
        lg.run(5000)                             # the plate closes the 0.5 mm gap in 2500 steps
        got = ev.take()
    begin = got[(got["kind"] == BEGIN) & got["wall"]]
    assert len(begin) >= 1
    print(f"begin at step {begin[0]['step']}, vn {begin[0]['vn']:.12f} m/s")
    assert begin[0]["vn"] == pytest.approx(V, rel=1e-9)
    assert np.allclose(begin[0]["n"], [0, 0, 1], atol=1e-9)


def test_the_recorder_adds_no_force_to_a_pour_with_insertions(tmp_path):
    """Spheres inserted every 400 steps into a box and settling: with the recorder's fix (which
    LIGGGHTS adds to the forces only at multiples of its napply, zeroed by the callback there)
    every position and velocity after 8,000 steps equals, bit for bit, the run without it, the
    inserted atoms' new slots of its array included."""
    def pour(folder, record: bool):
        with pile(folder, 0.03, -1.0, 400, 40) as lg:
            ev = ContactEvents(lg) if record else None
            lg.run(8000)
            got = ev.take() if record else None
            order = np.argsort(lg.atom("id"))
            return lg.atom("x")[order].copy(), lg.atom("v")[order].copy(), got

    x, v, got = pour(tmp_path / "with", True)
    x0, v0, _ = pour(tmp_path / "without", False)
    print(f"{len(x)} atoms, {int(np.sum(got['kind'] == BEGIN))} contacts begun")
    assert len(x) > 200 and np.sum(got["kind"] == BEGIN) > 1000
    assert np.array_equal(x, x0) and np.array_equal(v, v0)
