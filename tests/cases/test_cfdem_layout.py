"""A CFD-DEM case laid out and written as CFDEMcoupling's tutorials are (our own files, after
settlingTestMPI): case.toml inside the OpenFOAM folder (``case = "."``), the DEM script in
../DEM ending in ``run 0`` that the coupling drives, rho in 0/rho, pressure zeroGradient at
the walls, no [materials].dem table (the script sets the DEM values). One sphere settles
at the Di Felice terminal speed."""
import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import cfdem_case_toml
from foamlib import FoamFile
from scipy.optimize import brentq

from plugins.drag import LAWS
from pyhost.engines.fluid_case import box_case

pytestmark = pytest.mark.engines
ROOT = Path(__file__).resolve().parents[2]
D, RHO_P, RHO, NU = 1e-4, 3000.0, 10.0, 1e-5       # m, kg/m^3, kg/m^3, m^2/s (settlingTestMPI's)

SCRIPT = """# one sphere released in a closed column, coupled every 100 steps (a CFDEM-style run script)
log             ../DEM/log.liggghts
atom_style      granular
atom_modify     map array sort 0 0
communicate     single vel yes
boundary        f f f
newton          off
units           si
region          reg block 0 0.02 0 0.02 0 0.08 units box
create_box      1 reg
neighbor        0.0002 bin
neigh_modify    delay 0
fix         m1 all property/global youngsModulus peratomtype 5.e6
fix         m2 all property/global poissonsRatio peratomtype 0.45
fix         m3 all property/global coefficientRestitution peratomtypepair 1 0.3
fix         m4 all property/global coefficientFriction peratomtypepair 1 0.5
pair_style  gran model hertz tangential history
pair_coeff  * *
timestep    0.00001
fix         gravi all gravity 9.81 vector 0.0 0.0 -1.0
fix         zwalls1 all wall/gran model hertz tangential history primitive type 1 zplane 0.0
create_atoms    1 single 0.01 0.01 0.07 units box
set             group all diameter {d} density {rho_p}
variable    vz equal vz[1]
variable    time equal step*dt
fix         extra all print 100 "${{time}} ${{vz}}" file ../DEM/post/velocity.txt screen no
fix         integr all nve/sphere
run     0
run     0 upto
"""



def cfdem_case(root: Path, end: float = 0.1, time: str = "", dem: str = "") -> Path:
    """The two folders CFD/ and DEM/ as a CFDEM tutorial has them; returns CFD/."""
    cfd, dem_dir = root / "CFD", root / "DEM"
    walls = {f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo")}
    box_case(cfd, lo=(0, 0, 0), hi=(0.02, 0.02, 0.08), cells=(2, 2, 8), boundaries={**walls, "zhi": "outlet"},
             rho=RHO, nu=NU, dt=1e-3)
    props = FoamFile(cfd / "constant" / "transportProperties")
    del props["rho"]                                          # CFDEM keeps it in 0/rho
    rho = FoamFile(cfd / "0" / "rho")
    rho.class_, rho.object_ = "volScalarField", "rho"
    rho.update({"dimensions": FoamFile.DimensionSet(mass=1, length=-3), "internalField": RHO,
                "boundaryField": {".*": {"type": "zeroGradient"}}})
    p = FoamFile(cfd / "0" / "p")
    for face in walls:
        p["boundaryField"][face] = {"type": "zeroGradient"}
    FoamFile(cfd / "system" / "controlDict")["endTime"] = end
    (dem_dir / "post").mkdir(parents=True)
    (dem_dir / "in.liggghts_run").write_text(SCRIPT.format(d=D, rho_p=RHO_P))
    (cfd / "case.toml").write_text(cfdem_case_toml(fluid='drag = "difelice"\n', time="couple_every = 100\n" + time,
                                                   dem=dem))
    return cfd


def run(cfd: Path, *extra):
    return subprocess.run([sys.executable, "-m", "pyhost", "run", str(cfd), *extra], capture_output=True,
                          text=True, cwd=ROOT, timeout=600)


def velocities(cfd: Path) -> np.ndarray:
    return np.loadtxt(cfd.parent / "DEM" / "post" / "velocity.txt", comments="#", ndmin=2)


def terminal_speed() -> float:
    law = LAWS.lookup("difelice")
    weight = (RHO_P - RHO) * math.pi * D**3 / 6 * 9.81
    return brentq(lambda v: float(law(1.0, v, D, RHO, NU)) * v - weight, 1e-6, 10.0)


def test_cfdem_layout_settles_at_the_drag_law_speed(tmp_path):
    """Exit 0; the final ``run 0`` lasts the controlDict's endTime (0.1 s = 10,000 steps);
    the sphere falls at the Di Felice terminal speed within 1 % (its relaxation time is
    0.017 s); rho came from 0/rho; the output inside the case holds no copy of itself."""
    cfd = cfdem_case(tmp_path)
    r = run(cfd)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "which the coupling drives: 0.1 s (10000 steps" in r.stdout
    t, vz = velocities(cfd).T
    assert t[-1] == pytest.approx(0.1)
    print(f"settling speed {-vz[-1]:.6f} m/s, Di Felice {terminal_speed():.6f} m/s")
    assert -vz[-1] == pytest.approx(terminal_speed(), rel=0.01)
    copied = cfd / "output" / "fluid"
    assert (copied / "case.toml").exists() and not (copied / "output").exists()
    assert float(FoamFile(copied / "constant" / "transportProperties")["rho"].value) == RHO


def test_time_end_and_test_cut_the_driven_run(tmp_path):
    """[time] end sets the driven run's length; --test cuts it to a tenth, and cuts the
    script's first run as well."""
    cfd = cfdem_case(tmp_path, time="end = 0.05")
    r = run(cfd, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert velocities(cfd)[-1, 0] == pytest.approx(0.005)


@pytest.mark.long
def test_a_coupling_interval_longer_than_the_cases_deltaT_runs_in_its_steps(tmp_path):
    """The case's controlDict asks deltaT = 0.25 ms, a quarter of the coupling interval (100
    DEM steps of 10 us): the fluid advances each interval in 4 steps of 0.25 ms (as CFDEM's
    sub-steps), where the host used to replace deltaT by the interval; with deltaT = 1 ms, one
    step. Counted in the solver's own log over 0.01 s: 11 intervals (the fluid goes one
    interval ahead of the DEM at the start)."""
    steps = {}
    for dt in (2.5e-4, 1e-3):
        cfd = cfdem_case(tmp_path / str(dt), end=0.01)
        FoamFile(cfd / "system" / "controlDict")["deltaT"] = dt
        r = run(cfd)
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        log = (cfd / "output" / "fluid" / "log.collheatFoam").read_text()
        steps[dt] = sum(1 for line in log.splitlines() if line.startswith("Time = "))
    assert steps == {2.5e-4: 44, 1e-3: 11}


def test_dem_table_that_disagrees_with_the_script_is_refused(tmp_path):
    cfd = cfdem_case(tmp_path, dem="dem = { youngs_modulus = 1e7, restitution = 0.3 }")
    r = run(cfd)
    assert r.returncode == 2
    assert "materials.beads.dem.youngs_modulus = 1e+07 differs from the script's youngsModulus 5e+06" in r.stderr


def test_a_dry_script_whose_runs_simulate_nothing_is_refused(tmp_path):
    """Without a fluid nothing drives a 'run 0': exit 2 naming the script's last run, where
    the host used to end 'completed' after 0 s."""
    cfd = cfdem_case(tmp_path)
    toml = (cfd / "case.toml").read_text().replace("fluid = true", "fluid = false")
    (cfd / "case.toml").write_text(toml.replace('[fluid]\ncase = "."\ndrag = "difelice"\n', ""))
    r = run(cfd)
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    assert "the script's runs simulate no step" in r.stderr and "in.liggghts_run:" in r.stderr


@pytest.mark.long
def test_cfdem_layout_stopped_and_restarted_is_the_run_never_stopped(tmp_path):
    """The user's OpenFOAM case and script stopped by SIGTERM at step 5003 of the driven
    ``run 0 upto`` (no output.checkpoint: the signal writes one at the end of the coupling
    interval under way, step 5100), then --restart: the script replayed, the solver started
    from the saved fields, the rest of the driven run. history.csv, the VTK series and the
    summary equal byte for byte a run that wrote a checkpoint at that step; the sphere's
    velocity printed by the script's own fix print after the restart is the same to the last
    digit (the fix opens its file again, so it holds only the rows after the restart:
    docs/checkpoint.md)."""
    from conftest import STOPPER
    marked = cfdem_case(tmp_path / "marked")
    (marked / "case.toml").write_text((marked / "case.toml").read_text() + "\n[output]\ncheckpoint = 0.051\n")
    assert run(marked).returncode == 0
    cfd = cfdem_case(tmp_path / "cut")
    stopped = subprocess.run([sys.executable, "-c", STOPPER, "5003", "SIGTERM", "run", str(cfd)], capture_output=True,
                             text=True, cwd=ROOT, timeout=600)
    assert stopped.returncode == 143, stopped.stdout[-3000:] + stopped.stderr[-3000:]
    assert "checkpoint at t = 0.051 s (step 5100)" in stopped.stdout
    r = run(cfd, "--restart")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "restarted in this run, 4900 steps to go" in r.stdout

    def results(case):
        out = case / "output"
        files = ["history.csv", "summary.json"] + sorted(str(p.relative_to(out)) for p in (out / "vtk").rglob("*")
                                                          if p.is_file())
        return {f: (out / f).read_bytes() for f in files}

    got, want = results(cfd), results(marked)
    assert got.keys() == want.keys() and len(got) > 3
    assert {f: got[f] == want[f] for f in got} == dict.fromkeys(got, True)
    after = velocities(marked)
    after = after[after[:, 0] > 0.051 + 1e-9]
    assert np.array_equal(velocities(cfd), after)



def test_restart_after_the_fluid_cases_viscosity_changed_is_refused(tmp_path):
    """The user's OpenFOAM case is fingerprinted when the run starts, as the script is: its gas
    viscosity changed after a stop (constant/transportProperties, nu 1e-5 to 2e-5 m^2/s) is
    refused at --restart (exit 2) naming the file, before any engine starts: the checkpoint
    and the output as they were. (It used to be continued silently, with the old viscosity in
    the saved fields' case and the new one in the copy.)"""
    from conftest import STOPPER
    cfd = cfdem_case(tmp_path)
    stopped = subprocess.run([sys.executable, "-c", STOPPER, "303", "SIGTERM", "run", str(cfd)], capture_output=True,
                             text=True, cwd=ROOT, timeout=600)
    assert stopped.returncode == 143, stopped.stdout[-3000:] + stopped.stderr[-3000:]
    props = cfd / "constant" / "transportProperties"
    manifest = json.loads((cfd / "output" / "checkpoint" / "manifest.json").read_text())
    assert str(props) in manifest["inputs"] and str(cfd / "system" / "controlDict") in manifest["inputs"]
    FoamFile(props)["nu"] = FoamFile.Dimensioned(name="nu", value=2 * NU, dimensions=[0, 2, -1, 0, 0, 0, 0])
    before = {p: p.read_bytes() for p in sorted((cfd / "output").rglob("*")) if p.is_file()}
    r = run(cfd, "--restart")
    assert r.returncode == 2, r.stdout[-3000:] + r.stderr[-3000:]
    assert f"{props} is not the file the checkpoint's run read (changed since it started" in r.stderr
    assert {p: p.read_bytes() for p in sorted((cfd / "output").rglob("*")) if p.is_file()} == before

def cfdem_run1_case(root: Path, test_end: float) -> Path:
    """The layout with CFDEM's own coupling fixes and the script ending in ``run 1`` (as
    ErgunTestMPI_restart's and ErgunTestMPI_cgs's), the solver writing every 0.01 s of its own
    (controlDict), checkpoints every 0.01 s; --test runs ``test_end`` s."""
    cfd = cfdem_case(root, time=f"test_end = {test_end}\n")
    script = cfd.parent / "DEM" / "in.liggghts_run"
    text = script.read_text()
    script.write_text(text.replace("fix         integr all nve/sphere\nrun     0\nrun     0 upto\n",
                                   "fix         cfd all couple/cfd couple_every 100 mpi\n"
                                   "fix         cfd2 all couple/cfd/force/implicit\n"
                                   "fix         integr all nve/sphere\nrun     1\n"))
    assert "run     1\n" in script.read_text()
    control = FoamFile(cfd / "system" / "controlDict")
    control.update({"writeControl": "adjustableRunTime", "writeInterval": 0.01})
    (cfd / "case.toml").write_text((cfd / "case.toml").read_text() + "\n[output]\ncheckpoint = 0.01\n")
    return cfd


def test_cfdem_script_ending_in_run_1_is_driven_and_extends(tmp_path):
    """CFDEM runs a script whole, its closing ``run 1`` too, then drives the DEM for the
    controlDict's time: the host did the 1 step and ended with exit 0 (ErgunTestMPI_restart's
    fluid never moved). Now the run is the script's step, then the coupled time (--test: its
    0.01 s, 1000 steps). The finished run, extended by --restart --extend 0.01, is the run of
    0.02 s with the same checkpoints: it restarts at fluid time 0.011, so the solver's own
    writes (every 0.01 s from its start) fall on the checkpoints' times (that stopped the
    extended run with 'left 0 new time folders'); the first run's own writes stay in the
    output's copy of the case (the restart's new copy deleted them). Those writes are at other times than in the
    run never restarted (0.021 against 0.02 s), and the two differ from 0.014 s on at round-off,
    measured 1.8e-9 relative (history.csv; byte for byte without the case's own writes):
    1e-6 asked."""
    cfd = cfdem_run1_case(tmp_path / "a", 0.01)
    r = run(cfd, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "a CFDEM script (fix couple/cfd): its last run's 1 steps, then the coupling drives" in r.stdout
    assert json.loads((cfd / "output" / "summary.json").read_text())["steps"] == 1000
    assert (cfd / "output" / "fluid" / "0.01" / "U").is_file()        # the solver's own write
    r = run(cfd, "--test", "--restart", "--extend", "0.01")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    fluid = cfd / "output" / "fluid"       # the first run's writes kept (the restart copies the case anew)
    assert (fluid / "0.01" / "U").is_file() and (fluid / "0.021" / "U").is_file()
    assert not (cfd / "output" / ".fluid-earlier").exists()
    assert "--extend 0.01: 1000 steps more than the case asks" in r.stdout
    longer = cfdem_run1_case(tmp_path / "b", 0.02)
    r = run(longer, "--test")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]

    def results(case):
        out = case / "output"
        rows = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
        return rows, json.loads((out / "summary.json").read_text()), sorted(p.name for p in (out / "vtk").iterdir())

    (got, got_summary, got_vtk), (want, want_summary, want_vtk) = results(cfd), results(longer)
    assert got.dtype.names == want.dtype.names and len(got) == len(want) == 21 and got_vtk == want_vtk
    for name in got.dtype.names:
        np.testing.assert_allclose(got[name], want[name], rtol=1e-6, atol=0, equal_nan=True, err_msg=name)
    assert got_summary["steps"] == want_summary["steps"] == 2000
    assert got_summary["time"] == want_summary["time"]


def test_the_script_is_the_one_the_coupling_names(tmp_path):
    """A CFDEM case names the script its coupling runs (couplingProperties' twoWayMPIProps
    liggghtsPath, relative to CFD/, or under a "(regex)" key as ErgunTestMPI has it): a
    case.toml without [dem] takes it (periodicChannel's is in.liggghts_resume), and one that
    names none that exists is refused, naming the entry."""
    from pyhost.scene import SceneError, load_scene

    cfd = cfdem_case(tmp_path)
    toml = cfd / "case.toml"
    toml.write_text(toml.read_text().replace('[dem]\nscript = "../DEM/in.liggghts_run"\n', ""))
    (cfd.parent / "DEM" / "in.liggghts_run").rename(cfd.parent / "DEM" / "in.liggghts_resume")
    coupling = cfd / "constant" / "couplingProperties"
    coupling.write_text('FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n    object '
                        'couplingProperties;\n}\ndataExchangeModel twoWayMPI;\ncouplingInterval 100;\n'
                        'twoWayMPIProps\n{\n    liggghtsPath "../DEM/in.liggghts_resume";\n}\n')
    assert load_scene(toml).dem.script == "../DEM/in.liggghts_resume"
    # ErgunTestMPI's form: one dictionary for two exchange models, under a regular expression key
    coupling.write_text(coupling.read_text().replace("twoWayMPIProps\n", '"(twoWayMPIProps|M2MProps)"\n'))
    assert load_scene(toml).dem.script == "../DEM/in.liggghts_resume"
    coupling.write_text(coupling.read_text().replace("in.liggghts_resume", "in.liggghts_gone"))
    with pytest.raises(SceneError, match=r"dem.script: not given, and .*couplingProperties twoWayMPIProps "
                                         r"liggghtsPath names .*in.liggghts_gone, which does not exist"):
        load_scene(toml)


LIGGGHTS_COMMANDS = """FoamFile { version 2.0; format ascii; class dictionary; object liggghtsCommands; }

liggghtsCommandModels ( runLiggghts execute writeLiggghts execute );

executeProps1 { command ( set group all property/atom Temp number ); scalars ( 350 ); runFirst on; }

writeLiggghtsProps { path "../DEM/restarts"; writeName "r"; overwrite off; writeLastOnly off; writeEvery 2; }

executeProps3
{
    command ( set group all noBlanks property slash atom blanks Temp number );
    scalars ( 400 );
    runFirst off; runLast off; runEveryCouplingStep off; runEveryWriteStep off;
    startTime 0.0055; endTime 0.0085; timeInterval 1;
}
"""


def commands_case(root: Path) -> Path:
    """The layout run 10 ms with temperatures (300 K, collision heat A), the fluid writing every
    2 ms, and LIGGGHTS_COMMANDS; returns CFD/."""
    cfd = cfdem_case(root, end=0.01, dem="temperature = 300.0")
    toml = cfd / "case.toml"
    toml.write_text(toml.read_text().replace("[effects]\nfluid = true\n", '[effects]\nfluid = true\ncontact_heat = "A"\n'))
    FoamFile(cfd / "system" / "controlDict").update({"writeControl": "adjustableRunTime", "writeInterval": 0.002})
    (cfd / "constant" / "liggghtsCommands").write_text(LIGGGHTS_COMMANDS)
    return cfd


def test_the_cases_liggghtsCommands_run_where_cfdem_runs_them(tmp_path):
    """CFDEM runs a case's constant/liggghtsCommands after the DEM steps of a coupling step
    (packedBedTemp holds its bed at 600 K so; the host had left them out, exit 0). Here, over
    10 coupling steps of 1 ms: Temp set to 350 K at the first (runFirst), to 400 K at steps 5 to
    8 (startTime 0.0055, endTime 0.0085, timeInterval 1: CFDEM floors both to coupling steps),
    and a LIGGGHTS restart at every second of the fluid's writes (every 2 ms: 2, 6 and 10 ms,
    time-stamped as CFDEM's ``%f``). The frames see the sets at those times, the energy balance
    counts them as set by the script (m c 100 K, to 1e-12) and closes to 1e-12."""
    cfd = commands_case(tmp_path)
    r = run(cfd)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert "fluid time 0.001 s: " in r.stdout and "'set group all property/atom Temp 350.000000' (the case's liggghtsCommands" in r.stdout
    out = cfd / "output"
    rows = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    T = dict(zip(np.round(rows["time"], 6), rows["T_mean"]))
    assert T == {0.0: 300.0, 0.001: 350.0, 0.002: 350.0, 0.003: 350.0, 0.004: 350.0, 0.005: 400.0, 0.006: 400.0,
                 0.007: 400.0, 0.008: 400.0, 0.009: 400.0, 0.01: 400.0}
    s = json.loads((out / "summary.json").read_text())
    mc = RHO_P * math.pi * D**3 / 6 * 840.0
    assert s["energy_set_by_script"] == pytest.approx(mc * 100.0, rel=1e-12)
    assert abs(s["energy_balance_error"]) <= 1e-12
    assert s["case_commands_run"] == 1 + 4 + 3
    assert sorted(p.name for p in (cfd.parent / "DEM" / "restarts").iterdir()) == \
        ["r_0.002000", "r_0.006000", "r_0.010000"]


def test_a_liggghtsCommands_model_the_host_does_not_run_is_refused(tmp_path):
    """A model the host would leave out (setDEMGravity here) is refused before any engine
    starts, naming the file and the model: the run would not be the case's."""
    cfd = cfdem_case(tmp_path)
    (cfd / "constant" / "liggghtsCommands").write_text(
        LIGGGHTS_COMMANDS.split("liggghtsCommandModels")[0] + "liggghtsCommandModels ( runLiggghts setDEMGravity );\n")
    r = run(cfd)
    assert r.returncode == 2, r.stdout[-2000:] + r.stderr[-2000:]
    assert "constant/liggghtsCommands: liggghtsCommandModels: setDEMGravity: the host runs" in r.stderr
    assert not (cfd / "output" / "fluid").exists()


def restart_script() -> str:
    """The second stage's script: the first's, with the sphere read from the first stage's
    LIGGGHTS restart (CFDEM's writeLiggghts) in place of the box and the atom, printing into
    velocity2.txt, ending in one run 0."""
    text = SCRIPT.format(d=D, rho_p=RHO_P)
    head, tail = text.split("region ", 1)
    tail = tail.split("neighbor", 1)[1]
    text = head + "read_restart    ../DEM/stage1.restart\nneighbor" + tail
    text = re.sub(r"create_atoms.*\nset .*\n", "", text).replace("velocity.txt", "velocity2.txt")
    return text.replace("run     0\nrun     0 upto\n", "run     0\n")


def test_a_second_stage_goes_on_from_the_first_stages_fluid_and_dem(tmp_path):
    """CFDEM's restart in stages (ErgunTestMPI_restart): the first stage writes a LIGGGHTS
    restart at the fluid's last write (writeLiggghts, writeLastOnly) and the fluid its fields
    (every 5 ms; the host into OUT/fluid); the second starts at 5 ms (controlDict startTime)
    with a script reading that restart. It is refused (exit 2, before any engine) until the
    fluid's 0.005 folder is in the case, naming the copy to make; then the solver's first step
    is at 6 ms and the falling sphere's speed at 10 ms is the one run's to 1e-4. Measured
    2.7e-5: a LIGGGHTS restart sets its forces up anew, so the first half step after it kicks
    the sphere with the fluid force of the 5 ms exchange where the one run's still had the
    4 ms one's: dt/2 times their difference over the mass, 5e-6 s x 0.53 m/s^2 = 2.7e-6 m/s
    at 6 ms, the difference seen then and after (as in CFDEM's own restarts)."""
    cfd = cfdem_case(tmp_path / "one", end=0.01)
    FoamFile(cfd / "system" / "controlDict").update({"writeControl": "adjustableRunTime", "writeInterval": 0.005})
    whole = run(cfd)
    assert whole.returncode == 0, whole.stdout[-3000:] + whole.stderr[-3000:]
    cfd = cfdem_case(tmp_path / "two", end=0.005)
    FoamFile(cfd / "system" / "controlDict").update({"writeControl": "adjustableRunTime", "writeInterval": 0.005})
    (cfd / "constant" / "liggghtsCommands").write_text(
        LIGGGHTS_COMMANDS.split("liggghtsCommandModels")[0] + "liggghtsCommandModels ( runLiggghts writeLiggghts );\n"
        'writeLiggghtsProps { writeName "stage1.restart"; overwrite on; writeLastOnly on; }\n')
    first = run(cfd)
    assert first.returncode == 0, first.stdout[-3000:] + first.stderr[-3000:]
    assert (cfd.parent / "DEM" / "stage1.restart").is_file() and (cfd / "output" / "fluid" / "0.005" / "U").is_file()
    FoamFile(cfd / "system" / "controlDict").update({"startTime": 0.005, "endTime": 0.01})
    (cfd.parent / "DEM" / "in.liggghts_run").write_text(restart_script())
    refused = run(cfd, "--overwrite")
    assert refused.returncode == 2, refused.stdout[-2000:] + refused.stderr[-2000:]
    assert f"a run of the host wrote it in {cfd / 'output' / 'fluid' / '0.005'}: copy it into the case" in refused.stderr
    shutil.copytree(cfd / "output" / "fluid" / "0.005", cfd / "0.005")
    second = run(cfd, "--overwrite")
    assert second.returncode == 0, second.stdout[-3000:] + second.stderr[-3000:]
    log = (cfd / "output" / "fluid" / "log.collheatFoam").read_text()
    assert next(line for line in log.splitlines() if line.startswith("Time = ")) == "Time = 0.006"
    t, vz = np.loadtxt(cfd.parent / "DEM" / "post" / "velocity2.txt", comments="#", ndmin=2).T
    t1, vz1 = velocities(tmp_path / "one" / "CFD").T
    print(f"speed at 10 ms: second stage {vz[-1]:.9g}, one run {vz1[-1]:.9g} m/s")
    assert t[-1] == pytest.approx(0.01) and t1[-1] == pytest.approx(0.01)
    assert vz[-1] == pytest.approx(vz1[-1], rel=1e-4)


@pytest.mark.long
@pytest.mark.skipif(shutil.which("mpirun") is None, reason="no mpirun: tools/setup.sh --engines")
def test_the_cases_liggghtsCommands_on_two_ranks_as_serially(tmp_path):
    """The same liggghtsCommands under ``mpirun -np 2`` (LIGGGHTS' domain split, the commands
    ordered to both ranks): the same Temp history, the same energy set by the script, the same
    restart files, as the serial run."""
    import os
    results = {}
    for ranks in (1, 2):
        cfd = commands_case(tmp_path / str(ranks))
        cmd = [sys.executable, "-m", "pyhost", "run", str(cfd)]
        r = subprocess.run((["mpirun", "--oversubscribe", "-np", "2"] if ranks == 2 else []) + cmd, capture_output=True,
                           text=True, cwd=ROOT, timeout=600,
                           env=dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"))
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        rows = np.genfromtxt(cfd / "output" / "history.csv", delimiter=",", names=True)
        s = json.loads((cfd / "output" / "summary.json").read_text())
        results[ranks] = (list(rows["T_mean"]), s["energy_set_by_script"], s["case_commands_run"],
                          sorted(p.name for p in (cfd.parent / "DEM" / "restarts").iterdir()))
    log = (tmp_path / "2" / "CFD" / "output" / "dem" / "log.liggghts").read_text()
    grid = next(line for line in log.splitlines() if "MPI processor grid" in line).split("MPI")[0].split()
    assert int(grid[0]) * int(grid[2]) * int(grid[4]) == 2
    assert results[2] == results[1]


COUPLING = ('FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n    object couplingProperties;\n}\n'
            'dataExchangeModel twoWayMPI;\ncouplingInterval 100;\nvoidFractionModel divided;\n'
            'twoWayMPIProps\n{\n    liggghtsPath "../DEM/in.liggghts_run";\n}\n')


@pytest.mark.parametrize("damage, message", [
    # a ';' lost at the end of a line: the next entry read as part of this one's value
    (lambda t: t.replace("couplingInterval 100;", "couplingInterval 100"),
     r"couplingProperties:9: entry couplingInterval reads '100 voidFractionModel divided': a ';' is missing"),
    (lambda t: t.replace("twoWayMPIProps\n{\n", "twoWayMPIProps\n{\n    verbose true\n"),
     r"couplingProperties:13: entry twoWayMPIProps verbose reads 'True liggghtsPath \"\.\./DEM/in\.liggghts_run\"'"),
    # the case names another script than the scene's
    (lambda t: t.replace("in.liggghts_run", "in.liggghts_other"),
     r"dem.script: '\.\./DEM/in\.liggghts_run' .* but .*couplingProperties twoWayMPIProps liggghtsPath names "
     r".*in\.liggghts_other, which CFDEM's coupling runs"),
])
def test_cfdem_dictionaries_are_read_strictly(tmp_path, damage, message):
    """A CFDEM couplingProperties with a missing ';' was read with the next entry swallowed
    (voidFractionModel lost: CFDEM's default centre ran, exit 0), and a liggghtsPath naming
    another script than dem.script went unreported: both refused before any engine, naming
    the file, its line and the entry."""
    from pyhost.scene import SceneError, load_scene

    cfd = cfdem_case(tmp_path)
    (cfd.parent / "DEM" / "in.liggghts_other").write_text(SCRIPT.format(d=D, rho_p=RHO_P))
    (cfd / "constant" / "couplingProperties").write_text(damage(COUPLING))
    with pytest.raises((SceneError, ValueError), match=message):
        load_scene(cfd / "case.toml")


def test_an_unclosed_list_in_liggghtscommands_is_named_in_that_file(tmp_path):
    """liggghtsCommands with a list not closed: the message names that file (it named only
    case.toml), with foamlib's line."""
    from pyhost.scene import SceneError, load_scene

    cfd = cfdem_case(tmp_path)
    (cfd / "constant" / "liggghtsCommands").write_text(
        'FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n    object liggghtsCommands;\n}\n'
        'liggghtsCommandModels\n(\n    runLiggghts\n;\n')
    with pytest.raises(SceneError, match=r"case.toml: fluid.case: .*constant/liggghtsCommands: not a dictionary "
                                         r"OpenFOAM reads: .*line"):
        load_scene(cfd / "case.toml")


def test_a_particle_leaving_the_fluid_mesh_is_a_failed_simulation_naming_it(tmp_path):
    """A DEM box wider than the fluid's mesh (0.04 m against 0.02 m across) and the sphere
    thrown sideways at 5 m/s out of the mesh: the box's reach beyond the mesh is said at the
    start, and the run ends with exit 3 naming the particle, where it is and how fast it goes,
    and the likely cause; it was exit 2, bad input, naming 'index 0' only."""
    cfd = cfdem_case(tmp_path, end=0.05)
    script = cfd.parent / "DEM" / "in.liggghts_run"
    script.write_text(script.read_text().replace("region          reg block 0 0.02 0 0.02 0 0.08",
                                                 "region          reg block 0 0.04 0 0.02 0 0.08")
                      .replace("fix         integr all nve/sphere", "velocity all set 5.0 0 0\nfix         integr all nve/sphere"))
    r = run(cfd)
    assert r.returncode == 3, r.stdout[-3000:] + r.stderr[-3000:]
    assert ("warning: the DEM's box [0, 0, 0] .. [0.04, 0.02, 0.08] m reaches beyond the fluid's mesh (x hi by 0.02 m)"
            in r.stdout), r.stdout[-3000:]            # said at the start, before the sphere goes there
    assert re.search(r"1 particle\(s\) are outside the fluid's mesh, e.g. particle 1 at \[0\.02\d*, 0\.01, 0\.0\d+\] m "
                     r"moving at \[\d\.\d+, 0\.0, -?0\.\d+\] m/s: the DEM's walls and box do not keep the particles", r.stderr), r.stderr
    summary = json.loads((cfd / "output" / "summary.json").read_text())
    assert summary["status"].startswith("stopped at t = ") and "LeftTheMesh" in summary["status"]
