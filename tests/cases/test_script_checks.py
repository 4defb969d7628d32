"""Users' scripts the host used to run to a wrong or silent end: particles that grow (fix
adapt, as Debian's packing tutorial), a fix heat/gran defined after the first run (as CFDEM's
packedBedTemp), materials of types the script does not create, particles at 0 K."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import glass_toml

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]

HEAD = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block 0 0.02 0 0.02 0 0.02 units box
create_box {types} box
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype {E}
fix m2 all property/global poissonsRatio peratomtype {nu}
fix m3 all property/global coefficientRestitution peratomtypepair {types} {e}
fix m4 all property/global coefficientFriction peratomtypepair {types} {mu}
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-5
fix walls all wall/gran model hertz tangential history primitive type 1 zplane 0.0
fix walls2 all wall/gran model hertz tangential history primitive type 1 zplane 0.02
region fill block 0.002 0.018 0.002 0.018 0.002 0.018 units box
fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
fix pdd all particledistribution/discrete 15485867 1 pts 1.0
fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 0 insert_every once overlapcheck yes all_in yes particles_in_region 40 region fill
fix integr all nve/sphere
"""

GROW = """run 1
unfix ins
compute rad all property/atom radius
variable dgrown atom 2.0*1.0001*c_rad
fix grow all adapt 20 atom diameter v_dgrown
run 2000
unfix grow
run 500
"""


def header(types=1):
    n = types * types
    return HEAD.format(types=types, E=" ".join(["5e6"] * types), nu=" ".join(["0.3"] * types),
                       e=" ".join(["0.5"] * n), mu=" ".join(["0.5"] * n))


def toml(types="[1]", temperature="temperature = 300.0"):
    return f"""[dem]
script = "in.run"
[effects]
contact_heat = "A"
{glass_toml("glass", types, temperature)}[output]
vtk = false
pictures = false
"""


def run(tmp_path, script, case_toml, *options, ranks=1):
    (tmp_path / "in.run").write_text(script)
    (tmp_path / "case.toml").write_text(case_toml)
    cmd = [sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(tmp_path / "out"), *options]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "-np", str(ranks)] + cmd
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=600, env=env)
    summary = tmp_path / "out" / "summary.json"
    return r, json.loads(summary.read_text()) if summary.exists() else None


def test_growing_particles_enter_the_balance_as_a_mass_change(tmp_path):
    """40 spheres grow by 0.01 % of their diameter every 20 steps over 2000 steps (mass x 1.03)
    at one temperature: the balance closes to 1e-12 with the named term energy_mass_change =
    c T dm, where it used to end 'completed' with an error of the size of the growth."""
    r, s = run(tmp_path, header() + GROW, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    mass0 = 40 * 2500.0 * 4 / 3 * 3.141592653589793 * 0.001**3
    growth = s["sum_mcT_end"] / s["energy_in"] - 1                  # inserted in the first run
    print(f"m c T grew by {growth:.4%}; energy_mass_change {s['energy_mass_change']:.6g} J")
    assert s["energy_in"] == pytest.approx(840.0 * 300.0 * mass0, rel=1e-12)
    assert growth == pytest.approx(1.0001**303 - 1, rel=1e-3)       # d x 1.0001 at steps 0, 20, ..., 2000
    assert s["energy_mass_change"] == pytest.approx(s["sum_mcT_end"] - s["energy_in"], rel=1e-9)
    assert abs(s["energy_balance_error"]) < 1e-12


def test_heat_gran_after_the_first_run_has_its_capacities_checked(tmp_path):
    """fix heat/gran defined after 'run 0' with a thermalCapacity other than the material's:
    exit 2 naming both values and the property/global's line (the check used to run only at
    the first run; it named no line)."""
    late = """run 0
fix ftco all property/global thermalConductivity peratomtype 5.
fix ftca all property/global thermalCapacity peratomtype 0.1
fix heattransfer all heat/gran initial_temperature 600.
run 200
"""
    r, _ = run(tmp_path, header() + late, toml(temperature=""))
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    line = (header() + late).splitlines().index("fix ftca all property/global thermalCapacity peratomtype 0.1") + 1
    assert f"the script's thermalCapacity 0.1 ({tmp_path / 'in.run'}:{line})" in r.stderr, r.stderr   # the fix's line
    assert "differs from materials.glass.heat_capacity 840" in r.stderr


def test_material_of_a_type_the_script_does_not_create_is_refused_before_the_engines(tmp_path):
    r, s = run(tmp_path, header() + "run 100\n", toml(types="[1, 2]"))
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "materials.glass.types: atom type 2 does not exist: " in r.stderr and "in.run:8 creates 1 atom type" in r.stderr
    assert s is None and "host adds to the script" not in r.stdout     # no engine time spent


def test_a_script_without_units_si_is_refused_at_its_first_run(tmp_path):
    """Without a units command LIGGGHTS runs in lj units (a read_restart brings its file's): the
    host would read its lengths, masses and speeds as SI and give heat with exit 0. It reads
    LIGGGHTS' own unit style at the first run and refuses anything but si, before a step."""
    r, s = run(tmp_path, header().replace("units si\n", "") + "run 100\n", toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "in.run:24 (the first run): the script runs in LIGGGHTS' units lj" in r.stderr, r.stderr
    assert s is None


SPH = """atom_style sph
atom_modify map array sort 0 0
communicate single vel yes
boundary f f f
newton off
units si
lattice sc 0.01
region box block 0 0.1 0 0.1 0 0.1 units box
create_box 1 box
region fill block 0.01 0.05 0.01 0.05 0.01 0.05 units box
create_atoms 1 region fill
mass 1 0.001
neighbor 0.003 bin
fix m1 all property/global speedOfSound peratomtype 20.
fix m2 all property/global sl peratomtype 0.012
fix m3 all property/global artViscAlpha peratomtype 4.1666e-3
fix m4 all property/global artViscBeta peratomtype 0.
fix m5 all property/global artViscEta scalar 1.44e-6
fix m6 all property/global tensCorrEpsilon scalar 0.2
fix m7 all property/global tensCorrDeltaP peratomtype 0.01
pair_style sph/artVisc/tensCorr cubicspline 0.012 artVisc tensCorr
pair_coeff * *
timestep 1e-5
fix density all sph/density/continuity
fix pressure all sph/pressure Tait 60000. 1000. 7.
fix integr all nve/sph
set group all meso_rho 1000
set group all sphkernel cubicspline
run 10
"""


def test_a_script_of_other_particles_than_spheres_is_refused_at_its_first_run(tmp_path):
    """SPH particles (Debian's sph_1 and sph_2 tutorials: atom_style sph) have no radius: the
    contact recorder read LIGGGHTS' null radius array and the first run's trial copy crashed
    (SIGSEGV), reported as "LIGGGHTS refused 'run 0 post no': no message". LIGGGHTS' own atom
    style is read at the first run: exit 2 naming it, before a step."""
    r, s = run(tmp_path, SPH, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "in.run:29 (the first run): the script's atoms are LIGGGHTS' atom_style sph, not spheres" in r.stderr, \
        r.stderr[-3000:]
    assert "Segmentation fault" not in r.stdout + r.stderr and s is None


def test_particles_at_zero_kelvin_are_refused(tmp_path):
    """No fix heat/gran and no material temperature: the particles would start at 0 K."""
    r, _ = run(tmp_path, header() + "run 100\n", toml(temperature=""))
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "starts at 0 K: temperatures must be above 0 K; give materials.glass.temperature" in r.stderr


def test_liggghts_warnings_are_shown_once(tmp_path):
    """An insertion that cannot place all it is asked for warns in LIGGGHTS' screen log; the
    host shows the warning on its own output, once."""
    crowded = header().replace("particles_in_region 40", "particles_in_region 5000") + "run 100\nrun 100\n"
    r, _ = run(tmp_path, crowded, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    shown = [ln for ln in r.stdout.splitlines() if ln.startswith("LIGGGHTS WARNING") and "insert" in ln.lower()]
    print(shown)
    assert len(shown) == 1 and "each warning is shown once" in shown[0]


def test_a_warning_of_several_lines_is_shown_whole(tmp_path):
    """LIGGGHTS' whitelist warning (a contact model with rolling friction) is 'WARNING: ' and
    8 more lines up to its source location; it was echoed as 'LIGGGHTS WARNING:' and nothing
    else. The host shows it whole, on one line, ending at that location."""
    script = (header().replace("model hertz tangential history\npair_coeff",
                               "model hertz tangential history rolling_friction epsd2\npair_coeff")
              .replace("pair_style", "fix m7 all property/global coefficientRollingFriction peratomtypepair 1 0.1\n"
                                     "pair_style") + "run 100\n")
    r, _ = run(tmp_path, script, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    [shown] = [ln for ln in r.stdout.splitlines() if ln.startswith("LIGGGHTS WARNING")]
    print(shown)
    assert shown.startswith("LIGGGHTS WARNING: The contact model you specified is not located in any whitelist. ")
    assert "needs to be recompiled to generate the optimized code. (./src/contact_models.h:364) (after " in shown


def test_the_resolved_scene_is_one_line_naming_its_file(tmp_path):
    """The resolved scene, 150 lines of JSON printed before the run, is in OUT/scene.json;
    the screen says so in one line."""
    r, _ = run(tmp_path, header() + "run 100\n", toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    lines = r.stdout.splitlines()
    assert lines[0] == f"scene: {tmp_path / 'case.toml'}, resolved in {tmp_path / 'out' / 'scene.json'}"
    assert lines[1].startswith("active effects: ")
    assert json.loads((tmp_path / "out" / "scene.json").read_text())["path"] == str(tmp_path / "case.toml")


@pytest.mark.parametrize("runs, message", [
    ("run 1e11\n", "run 1e11: 100000000000 steps is outside 0 .. 2^31 - 1"),
    ("run -100\n", "run -100: -100 steps is outside 0 .. 2^31 - 1"),
    ("variable n equal 300.7\nrun ${n}\n", "run ${n}: 300.7 is not a whole number of steps"),
    ("run 200\nrun 100 upto\n", "run 100 upto: step 100 is before the current step 200"),
    ("variable w string hello\nrun ${w}\n", "run ${w}: "),
    ("run ${undefined}\n", "run ${undefined}: "),
])
def test_run_commands_keep_liggghts_rules(tmp_path, runs, message):
    """'run N' as LIGGGHTS runs it: a whole N from 0 to 2^31 - 1, an 'upto' step not in the
    past; refused naming the script's line (they were chunked until killed, rounded, or
    skipped in silence)."""
    r, _ = run(tmp_path, header() + runs, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert message in r.stderr and "in.run:" in r.stderr


def test_a_zero_time_step_is_refused(tmp_path):
    """Named at its own line (17), not at the first run's (26) where it was found."""
    r, _ = run(tmp_path, header().replace("timestep 1e-5", "timestep 0") + "run 100\n", toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "in.run:17: 'timestep 0': the time step is 0 s" in r.stderr, r.stderr


HEAT = "fix m5 all property/global thermalCapacity peratomtype 840\nfix ht all heat/gran initial_temperature 300.\n"


@pytest.mark.parametrize("where, value", [("before", "-50"), ("between", "-50"), ("between", "0")])
def test_a_temperature_set_at_or_below_0_K_is_refused(tmp_path, where, value):
    """A script's 'set ... property/atom Temp -50' (or 0), before the first run or between
    two: LIGGGHTS takes it and the run went on at -50 K with exit 0; refused at the set's own
    line (28 or 29) with the value, as a particle starting at 0 K is."""
    conduct = header() + "fix m6 all property/global thermalConductivity peratomtype 1.0\n" + HEAT
    bad = f"set group all property/atom Temp {value}\n"
    script = conduct + (bad + "run 100\n" if where == "before" else "run 100\n" + bad + "run 100\n")
    line = script.splitlines().index(bad.strip()) + 1
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert f"in.run:{line}: '{bad.strip()}': {value} K: temperatures must be above 0 K" in r.stderr, r.stderr
    if where == "between":              # the run before it kept: summary.json of its 100 steps
        assert s["steps"] == 100 and s["status"].startswith("stopped at t = ")


def test_a_fix_refused_at_the_first_run_is_named_at_its_own_line(tmp_path):
    """A fix heat/gran without the script's thermalConductivity: LIGGGHTS takes the fix and
    refuses it at the first run's set-up; the message named the run's line (27), it names the
    fix's (26) and the run where it was refused."""
    script = header() + HEAT + "run 100\n"
    assert script.splitlines()[25].startswith("fix ht all heat/gran") and script.splitlines()[26] == "run 100"
    r, _ = run(tmp_path, script, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "in.run:26 ('fix ht all heat/gran initial_temperature 300.', refused at " in r.stderr, r.stderr
    assert "in.run:27's set-up) (the first run)" in r.stderr and "thermalConductivity" in r.stderr


def test_a_command_liggghts_refuses_mid_script_is_named_with_its_line(tmp_path):
    """The set-up's commands are tried together in one forked copy: a bad one in the middle
    (line 17 of the 25 before the run) still stops the run with exit 2, naming its file, line
    and LIGGGHTS' own message."""
    script = header().replace("pair_coeff * *\n", "pair_coeff * *\nfix bad all bogus 1 2 3\n") + "run 100\n"
    assert script.splitlines()[16] == "fix bad all bogus 1 2 3" and len(script.splitlines()) == 26
    r, _ = run(tmp_path, script, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "in.run:17" in r.stderr and 'Invalid fix style: "bogus"' in r.stderr, r.stderr[-2000:]


def test_smoke_run_cuts_the_first_run(tmp_path):
    """--test with time.test_end = 1 ms stops the script's first (and only) run of 50,000
    steps after 100 (it used to cut only the runs after the first)."""
    r, s = run(tmp_path, header() + "run 50000\n", toml() + "[time]\ntest_end = 0.001\n", "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert s["steps"] == 100 and s["time"] == pytest.approx(0.001)


def test_a_density_other_than_the_materials_is_refused(tmp_path):
    """The script's particle template says 2500 kg/m^3, case.toml 2700: refused at their
    insertion, naming both (it was accepted silently; the models would use 2700)."""
    r, _ = run(tmp_path, header() + "run 100\n", toml().replace("density = 2500.0", "density = 2700.0"))
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "has the script's density 2500 kg/m^3, materials.glass.density is 2700" in r.stderr


def test_a_type_without_material_mid_run_still_leaves_a_summary(tmp_path):
    """Particles of a type no material names, inserted by a later part of the script: exit 2
    naming the type, and summary.json of what was done before (there was none)."""
    script = header(types=2) + "run 200\n" + \
        "create_atoms 2 single 0.01 0.01 0.019 units box\nset type 2 diameter 0.002 density 2500\nrun 200\n"
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert "atom type(s) [2] have no material" in r.stderr
    assert s is not None and s["status"].startswith("stopped at t = ") and s["steps"] == 200


LOSE = """create_atoms 1 single 0.01 0.01 0.01 units box
create_atoms 1 single 0.005 0.01 0.01 units box
set type 1 diameter 0.002 density 2500
fix integr all nve/sphere
thermo_modify lost error
thermo 10
run 200
velocity all set 20.0 0 0
run 5000
"""


@pytest.mark.parametrize("ranks", [1, 2])
def test_lost_atoms_in_a_later_chunk_end_with_a_summary(tmp_path, ranks):
    """Spheres thrown out through an open face in the middle of a long run, with the
    script's 'thermo_modify lost error': LIGGGHTS' "Lost atoms" error comes while stepping (a
    chunk's set-up alone is tried in a forked copy). It used to end the process (exit 1, no
    summary.json; under mpirun with no script line); now exit 3 naming the script's line and
    LIGGGHTS' message, with the summary of the steps done (the chunk under way not counted),
    on one rank and on two."""
    if ranks > 1 and shutil.which("mpirun") is None:
        pytest.fail("no mpirun: tools/setup.sh --engines installs it")
    script = HEAD.split("region fill")[0].format(types=1, E="5e6", nu="0.3", e="0.5", mu="0.5") + LOSE
    r, s = run(tmp_path, script, toml(), ranks=ranks)
    assert r.returncode == 3, r.stdout[-3000:] + r.stderr[-3000:]
    last = len(script.splitlines())
    assert f"in.run:{last}: during the run, at step " in r.stderr and "ERROR: Lost atoms" in r.stderr
    assert s is not None and s["status"].startswith("stopped at t = ")
    # 20 m/s from x = 0.005 m over 0.015 m to the open face: gone by step 200 + 75 (thermo every 10)
    assert 200 <= s["steps"] <= 200 + 75 + 10, s["steps"]


FLOOR = """solid floor
facet normal 0 0 1
outer loop
vertex 0 0 0.001
vertex 0.02 0 0.001
vertex 0.02 0.02 0.001
endloop
endfacet
facet normal 0 0 1
outer loop
vertex 0 0 0.001
vertex 0.02 0.02 0.001
vertex 0 0.02 0.001
endloop
endfacet
endsolid floor
"""


def test_a_script_may_unfix_its_mesh_wall(tmp_path):
    """A mesh floor that the script removes between runs (valid in plain LIGGGHTS): the
    compute wall/gran/local the host adds for it used to make the 'unfix' fail. Particles
    fall on the floor (collisions with it are seen), the floor goes, they fall to the
    primitive wall below."""
    (tmp_path / "floor.stl").write_text(FLOOR)
    head = header().replace("fix walls all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n",
                            "fix gravi all gravity 9.81 vector 0 0 -1\n"
                            "fix cad all mesh/surface file floor.stl type 1\n"
                            "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad\n"
                            "fix walls all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n")
    r, s = run(tmp_path, head + "run 3000\nunfix floor\nrun 1000\n", toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert s["particle_wall"] > 0 and s["steps"] == 4000
    assert abs(s["energy_balance_error"]) < 1e-9


def test_the_scripts_own_dumps_have_the_frames_of_a_native_run(tmp_path):
    """A script's 'dump local' and 'dump custom', with heat/gran and a run of ${n} steps: the
    host's run writes the same frames (time steps) as 'liggghts -in' does, none twice (the
    issue catalogue reported two duplicate frames)."""
    if shutil.which("liggghts") is None:
        pytest.fail("no liggghts: tools/setup.sh --engines installs it")
    heat = ("fix m5 all property/global thermalConductivity peratomtype 1.0\n"
            "fix m6 all property/global thermalCapacity peratomtype 840\n"
            "fix ht all heat/gran initial_temperature 300\nfix integr")
    script = header().replace("fix integr", heat) + (
        "compute cp all pair/gran/local pos vel id delta\n"
        "dump dl all local 100 pair.dump c_cp[1] c_cp[2]\ndump da all custom 100 atoms.dump id x y z\n"
        "variable n equal 1000\nrun ${n}\nrun 500\n")
    native = tmp_path / "native"
    native.mkdir()
    (native / "in.run").write_text(script)
    subprocess.run(["liggghts", "-in", "in.run", "-log", "none", "-screen", "/dev/null"], cwd=native, check=True,
                   timeout=300)
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    def steps(dump):
        lines = dump.read_text().splitlines()
        return [lines[k + 1] for k, ln in enumerate(lines) if ln == "ITEM: TIMESTEP"]

    for name in ("pair.dump", "atoms.dump"):
        assert steps(tmp_path / name) == steps(native / name) == [str(k) for k in range(0, 1501, 100)]


def test_an_error_of_one_rank_names_the_script_line(tmp_path):
    """Under mpirun, an error LIGGGHTS raises on one rank alone (Error::one: a 'fix print'
    reaching an undefined variable) ends every rank through MPI_Abort and cannot leave a
    summary; it used to name no script line (and a rank without a screen said nothing). Now
    stderr has LIGGGHTS' message, the rank, and the script's file, line and command."""
    if shutil.which("mpirun") is None:
        pytest.fail("no mpirun: tools/setup.sh --engines installs it")
    script = header() + 'run 200\nfix pr all print 300 "value ${nothere}"\nrun 5000\n'
    r, _ = run(tmp_path, script, toml(), ranks=2)
    assert r.returncode != 0
    last = len(script.splitlines())
    assert f"LIGGGHTS ended the process at {tmp_path}/in.run:{last} (run 5000): ERROR on proc" in r.stderr, r.stderr
    assert "Substitution for illegal variable" in r.stderr


def test_a_cfdem_tutorials_first_stage_is_named(tmp_path):
    """A read_restart of the file a CFDEM tutorial's first stage (in.liggghts_init, plain
    LIGGGHTS) writes, run before that stage: exit 2, LIGGGHTS' message and what to do."""
    (tmp_path / "in.liggghts_init").write_text("# the tutorial's first stage\n")
    r, _ = run(tmp_path, "read_restart post/restart/liggghts.restart\n" + header() + "run 10\n", toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    for w in ("in.run:1", "Cannot open restart file", "run 'liggghts -in in.liggghts_init'"):
        assert w in r.stderr, (w, r.stderr[-2000:])


def test_a_processor_grid_for_other_ranks_is_left_out(tmp_path):
    """'processors 2 2 1' (ErgunTestMPI's, for 4 ranks) on one rank, which LIGGGHTS refuses:
    the host leaves it out, says so, and the run ends as without it (the grid only divides
    the box among ranks): the same collisions as without it."""
    script = header() + "fix gravi all gravity 9.81 vector 0 0 -1\nrun 4000\n"       # the 40 beads land
    r, with_grid = run(tmp_path, "processors 2 2 1\n" + script, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "in.run:1: 'processors 2 2 1' is a grid of 4 ranks and this run has 1: left out" in r.stdout
    plain = tmp_path / "plain"
    plain.mkdir()
    r, without = run(plain, script, toml())
    assert r.returncode == 0 and with_grid["collisions"] > 20
    assert with_grid["collisions"] == without["collisions"] and with_grid["particle_wall"] == without["particle_wall"]


@pytest.mark.parametrize("command, message", [
    ("unfix collheat_events", "ids beginning with 'collheat_' are the host's own"),
    ("fix collheat_events all nve/sphere", "ids beginning with 'collheat_' are the host's own"),
    ("compute collheat_pairs all pair/gran/local id", "ids beginning with 'collheat_' are the host's own"),
    ('if "1 > 0" then "unfix collheat_events"', "ids beginning with 'collheat_' are the host's own"),
    ("unfix Temp", "'unfix Temp': the particles' temperatures live in the Temp property"),
    ("fix Temp all property/atom Temp scalar yes yes no 500.0", "the host adds 'fix Temp all property/atom Temp' at")])
def test_a_script_may_not_remove_or_replace_the_hosts_fixes(tmp_path, command, message):
    """The host adds its contact recorder (fix collheat_events) and, where the script has none,
    the Temp property at the first run. A script that unfixed the recorder after it ran on to
    exit 0 with 244 collisions instead of 397 and no heat moved. Now such a command (its id
    with the host's prefix, or Temp) is refused when the script is read, before any engine
    time: exit 2 naming the file and line."""
    script = header() + "fix gravi all gravity 9.81 vector 0 0 -1\nrun 100\n" + command + "\nrun 100\n"
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert f"in.run:{len(script.splitlines()) - 1}: " in r.stderr and message in r.stderr, r.stderr[-2000:]
    assert s is None and "host adds to the script" not in r.stdout      # refused before LIGGGHTS ran


@pytest.mark.parametrize("ranks", [1, 2])
def test_two_mesh_wall_fixes_are_refused_with_exit_2_on_any_number_of_ranks(tmp_path, ranks):
    """Two fix wall/gran over meshes, which LIGGGHTS refuses at a run's set-up ('More than one
    wall of type mesh'): exit 2 serially (the set-up is tried in a forked copy first), and
    on two ranks, where no copy tries it, it was exit 3 'simulation failed at step 0'. Plain
    'liggghts -in' refuses the same script with the same ERROR line."""
    if ranks > 1 and shutil.which("mpirun") is None:
        pytest.fail("no mpirun: tools/setup.sh --engines installs it")
    (tmp_path / "floor.stl").write_text(FLOOR)
    (tmp_path / "roof.stl").write_text(FLOOR.replace(" 0.001\n", " 0.019\n"))
    script = header().replace("fix walls all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n",
                              "fix cad all mesh/surface file floor.stl type 1\n"
                              "fix cad2 all mesh/surface file roof.stl type 1\n"
                              "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad\n"
                              "fix roof all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad2\n")
    script += "run 100\n"
    refusal = "ERROR: Fix wall/gran (id floor): More than one wall of type 'mesh' is not supported"
    (tmp_path / "in.run").write_text(script)
    native = subprocess.run(["liggghts", "-in", "in.run", "-log", "none"], cwd=tmp_path, capture_output=True,
                            text=True, errors="replace", timeout=120)     # (its banner is not all UTF-8)
    assert refusal in native.stdout
    r, s = run(tmp_path, script, toml(), ranks=ranks)
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    floor = next(k for k, line in enumerate(script.splitlines(), 1) if line.startswith("fix floor"))
    assert (f"in.run:{floor} ('fix floor all wall/gran" in r.stderr            # the fix LIGGGHTS names, at its line
            and f"refused at {tmp_path / 'in.run'}:{len(script.splitlines())}'s set-up" in r.stderr
            and refusal in r.stderr), r.stderr
    assert s is None
