# Every VTK module of pyvista's wheel is loaded (and its symbols bound) before any test opens
# LIGGGHTS in this process: Debian's libliggghts brings Debian's VTK 9.1 into the global
# symbol scope, and a pip VTK module loaded after it bound some symbols there (a reader's
# segfault in tests/unit/test_dumps.py after tests/engines/test_contact_events.py).
import vtkmodules.all  # noqa: F401,E402
import pytest

from plugins.heat import Pair


@pytest.fixture
def paper_pair():
    """The paper's parameter set (sec. 6), particle-particle."""
    return Pair()


FLOOR_STL = """solid floor
facet normal 0 0 1
outer loop
vertex -0.01 -0.01 0
vertex 0.01 -0.01 0
vertex 0.01 0.01 0
endloop
endfacet
facet normal 0 0 1
outer loop
vertex -0.01 -0.01 0
vertex 0.01 0.01 0
vertex -0.01 0.01 0
endloop
endfacet
endsolid floor
"""

POUR_SCRIPT = """# a user-style pour: insertion, two types and sizes, an STL floor, periodic sides
atom_style granular
atom_modify map array
boundary p p f
newton off
communicate single vel yes
units si
region box block -0.01 0.01 -0.01 0.01 -0.001 0.03 units box
create_box 2 box
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 2 0.8 0.8 0.8 0.8
fix m4 all property/global coefficientFriction peratomtypepair 2 0.3 0.3 0.3 0.3
fix m5 all property/global thermalConductivity peratomtype 1.0 1.0
fix m6 all property/global thermalCapacity peratomtype 800 800
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-5
fix gravi all gravity 9.81 vector 0 0 -1
fix floor all mesh/surface file floor.stl type 1
fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes floor
fix heat all heat/gran initial_temperature 300
fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
fix pts2 all particletemplate/sphere 15485867 atom_type 2 density constant 2500 radius constant 0.0015
fix pdd all particledistribution/discrete 32452843 2 pts1 0.5 pts2 0.5
region ins block -0.009 0.009 -0.009 0.009 0.01 0.028 units box
fix ins all insert/rate/region seed 49979687 distributiontemplate pdd nparticles 60 &
    particlerate 6000 insert_every 200 overlapcheck yes vel constant 0 0 -0.5 region ins
fix integr all nve/sphere
compute cp all pair/gran/local delta id vel pos     # typed out of LIGGGHTS' order on purpose
compute cw all wall/gran/local vel id pos delta
thermo 1000
dump d1 all custom 500 post/dump.* id type x y z vx vy vz radius f_Temp[0]
dump d2 all custom 500 post/all.dump vx vy vz radius id type z x y f_Temp
dump d3 all custom 20 post/fine.dump id type x y z vx vy vz radius
dump dv all custom/vtk 500 post/p_*.vtk id type x y z vx vy vz radius
dump dl all local 20 post/pair.* {pair}
dump dw all local 20 post/wall.* {wall}
dump dl1 all local 1 post/pairs_every_step.dump {pair}
dump dw1 all local 1 post/walls_every_step.dump {wall}
run 6000
"""


SOFT_DEM = "{ youngs_modulus = 5e6, restitution = 0.8, poisson_ratio = 0.3 }"
"""A softened DEM contact for a material table (dem = ...)."""


def steel_toml(dem: str = SOFT_DEM) -> str:
    """A case.toml [materials.steel] table: the steel of the paper's examples (SI), with the
    DEM's softened contact ``dem``."""
    return f"""[materials.steel]
density = 7800.0
youngs_modulus = 210e9
poisson_ratio = 0.3
yield_stress = 300e6
heat_capacity = 470.0
conductivity = 45.0
dem = {dem}
"""


def steel_material(dem=None):
    """The same steel as a pyhost.scene.Material (DEM contact: 1e7 Pa, e = 0.9 unless given)."""
    from pyhost.schema import DemContact, Material
    return Material(7800.0, 210e9, 0.3, 300e6, 470.0, 45.0, dem or DemContact(youngs_modulus=1e7, restitution=0.9))


def glass_toml(name: str = "glass", types: str = "[1]", temperature: str = "temperature = 300.0") -> str:
    """A case.toml [materials.NAME] table of soda-lime glass (SI), for users' scripts whose
    particles are glass beads of density 2500 kg/m^3."""
    return f"""[materials.{name}]
types = {types}
{temperature}
density = 2500.0
youngs_modulus = 63e9
poisson_ratio = 0.25
yield_stress = 500e6
heat_capacity = 840.0
conductivity = 1.0
"""


@pytest.fixture(scope="session")
def pour_dumps(tmp_path_factory):
    """Dumps of a 60-particle pour on Debian's LIGGGHTS (about 1 s): post/dump.* (one step a
    file, f_Temp[0]), post/all.dump (every step in one file, scrambled columns, f_Temp),
    post/p_*.vtk (custom/vtk), post/fine.dump (every 20 steps), post/pair.* and post/wall.* (contacts every 20 steps),
    post/pairs_every_step.dump and post/walls_every_step.dump (contacts at every step, one file each)."""
    import shutil
    import subprocess

    if shutil.which("liggghts") is None:
        pytest.skip("liggghts not installed")
    folder = tmp_path_factory.mktemp("pour")
    (folder / "post").mkdir()
    (folder / "floor.stl").write_text(FLOOR_STL)
    local = lambda c: " ".join(f"c_{c}[{k}]" for k in range(1, 17))
    (folder / "in.pour").write_text(POUR_SCRIPT.format(pair=local("cp"), wall=local("cw")))
    run = subprocess.run(["liggghts", "-in", "in.pour", "-log", "log.liggghts", "-screen", "/dev/null"],
                         cwd=folder, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, (folder / "log.liggghts").read_text()[-2000:]
    return folder


# Tests that load LIGGGHTS into the pytest process itself. Debian's libliggghts brings
# Debian's VTK into the global symbol scope, and pip's VTK (pyvista) then crashes reading a
# legacy VTK file in the same process. So they run last, after every test that uses pyvista.
IN_PROCESS_ENGINE = ("tests/engines/test_liggghts.py",
                     "tests/cases/test_small_cases.py::test_results_so_far_survive_a_failure")


def pytest_collection_modifyitems(config, items):
    last = [item for item in items if item.nodeid.startswith(IN_PROCESS_ENGINE)]
    items[:] = [item for item in items if item not in last] + last


def once(tmp_path_factory, name: str, make):
    """The folder ``make(folder)`` fills, made once in a test session whichever of pytest-xdist's
    workers asks first (the others wait for it and take it): a module's fixture would be built
    by each worker that runs one of its tests (the 4-minute packed bed twice). A ``make`` that
    fails leaves no folder: the next asker tries again (and fails the same way)."""
    import fcntl
    import os
    import shutil

    base = tmp_path_factory.getbasetemp()
    root = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base    # (the workers' common folder)
    folder = root / f"once-{name}"
    with open(root / f"once-{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / ".done").exists():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            make(folder)
            (folder / ".done").write_text("")
    return folder


# ``python -c STOPPER STEP SIGNAL run CASE ...``: pyhost's CLI, whose DEM sends itself SIGNAL (a
# name: SIGTERM, SIGKILL, ...) after the first chunk that reaches STEP (a batch system's stop).
STOPPER = """
import os, signal, sys
import pyhost.world as r
from pyhost.cli import main
at, sig = int(sys.argv[1]), getattr(signal, sys.argv[2])
class Stopping:
    def __init__(self, dem): self.dem = dem
    def run(self, n):
        self.dem.run(n)
        if self.dem.step >= at: os.kill(os.getpid(), sig)
    def __getattr__(self, name): return getattr(self.dem, name)
simulate = r.simulate
r.simulate = lambda *a, **k: simulate(*a, wrap=Stopping, **k)
sys.exit(main(sys.argv[3:]))
"""


def cfdem_case_toml(fluid: str = "", time: str = "", dem: str = "") -> str:
    """The case.toml of a CFDEM layout (in CFD/, the script in ../DEM/in.liggghts_run): a
    settlingTestMPI-like bead of 3000 kg/m^3; ``fluid``, ``time`` and ``dem`` are lines added to
    [fluid], [time] and the material's table."""
    return f"""[dem]
script = "../DEM/in.liggghts_run"

[effects]
fluid = true

[fluid]
case = "."
{fluid}
[time]
{time}
[materials.beads]
types = [1]
density = 3000.0
youngs_modulus = 63e9
poisson_ratio = 0.25
yield_stress = 500e6
heat_capacity = 840.0
conductivity = 1.0
{dem}
"""


# A small pour (the smallest that shows an insertion restarted): glass beads of 1 mm inserted
# into a 16 mm cylinder over a floor at 400 K, 3000 steps of 1e-5 s, a checkpoint at 0.015 s.
POUR = """atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
region box block -0.01 0.01 -0.01 0.01 0 0.03 units box
create_box 1 box
neighbor 0.0005 bin
neigh_modify delay 0
fix m1 all property/global youngsModulus peratomtype 5e6
fix m2 all property/global poissonsRatio peratomtype 0.3
fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5
fix m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style gran model hertz tangential history
pair_coeff * *
timestep 1e-5
fix gravi all gravity 9.81 vector 0 0 -1
fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0
fix sides all wall/gran model hertz tangential history primitive type 1 zcylinder 0.008 0 0
fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001
fix pdd all particledistribution/discrete 15485867 1 pts 1.0
region fill cylinder z 0 0 0.007 0.002 0.02 units box
{insert}
fix integr all nve/sphere
run 3000
"""
POUR_TOML = f"""[dem]
script = "in.pour"
[effects]
contact_heat = "A"
{glass_toml()}[[walls]]
fix = "floor"
material = "glass"
temperature = 400.0
[output]
vtk = false
pictures = false
checkpoint = 0.015
"""
# a square insertion face of 10 mm at z = 12 mm, for insert/stream
FACE = "solid face\n" + "".join(
    f"facet normal 0 0 -1\nouter loop\n" + "".join(f"vertex {x} {y} 0.012\n" for x, y in tri) + "endloop\nendfacet\n"
    for tri in (((-0.005, -0.005), (0.005, -0.005), (0.005, 0.005)), ((-0.005, -0.005), (0.005, 0.005), (-0.005, 0.005)))
) + "endsolid face\n"
INSERTIONS = {
    # inserts 50 at step 1, then never again
    "pack_once": "fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 -0.5 "
                 "insert_every once overlapcheck yes all_in yes particles_in_region 50 region fill",
    # tops the region up to 30 at steps 1, 1001, 2001
    "pack_every": "fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 -0.5 "
                  "insert_every 1000 overlapcheck yes all_in yes particles_in_region 30 region fill",
    # 60 in two lots of 30 (steps 1 and 501): done before the checkpoint
    "rate": "fix ins all insert/rate/region seed 32452843 distributiontemplate pdd nparticles 60 particlerate 6000 "
            "insert_every 500 overlapcheck yes all_in yes vel constant 0 0 -0.5 region fill",
    # 60 through the face, in lots of 48 (step 1) and 12 (step 801, released by step 1601: some
    # still in their extrusion at the checkpoint, step 1500)
    "stream": "fix inface all mesh/surface file face.stl type 1\nfix ins all insert/stream seed 32452843 "
              "distributiontemplate pdd nparticles 60 particlerate 6000 overlapcheck yes vel constant 0 0 -0.5 "
              "insertion_face inface extrude_length 0.004",
}


def pour(tmp, insertion: str):
    """A case folder in ``tmp`` of the pour with the insertion ``INSERTIONS[insertion]``."""
    folder = tmp / f"pour-{insertion}"
    folder.mkdir(parents=True)
    (folder / "in.pour").write_text(POUR.format(insert=INSERTIONS[insertion]))
    (folder / "face.stl").write_text(FACE)
    (folder / "case.toml").write_text(POUR_TOML)
    return folder
