"""CFDEM's liggghtsCommands read as CFDEMcoupling-PUBLIC reads them (pyhost.engines.cfdem_commands):
the command composed from its words, when each runs, what is refused. The tutorials' own files
are quoted here (packedBedTemp's execute, settlingTestMPI's writeLiggghts)."""
import pytest

from pyhost.engines.cfdem_commands import CaseCommandsError, compose, read_commands, write_times

PACKED_BED = """liggghtsCommandModels ( runLiggghts execute );
executeProps1
{
    command ( set region total noBlanks property slash atom // former peratom
              blanks Temp number );
    scalars ( 600 );
    runFirst off;
    runLast off;
    runEveryCouplingStep on;
}
"""
SETTLING = """liggghtsCommandModels ( runLiggghts writeLiggghts );
writeLiggghtsProps { writeLastOnly off; path "../DEM/post/restart"; overwrite on; verbose; }
"""


def commands(tmp_path, text, couple_every=500):
    (tmp_path / "constant").mkdir(exist_ok=True)
    (tmp_path / "constant" / "liggghtsCommands").write_text(text)
    return read_commands(tmp_path, couple_every)


def test_packed_bed_temp_holds_its_bed_at_600_K_at_every_coupling_step(tmp_path):
    (c,) = commands(tmp_path, PACKED_BED)
    assert c.text == "set region total property/atom Temp 600.000000" and not c.stamp
    assert [k for k in range(1, 6) if c.due(k, 300, 0, False, 0.0, 1e-5, 500)] == [1, 2, 3, 4, 5]
    assert c.line == 2 and c.where.endswith("constant/liggghtsCommands:2")


def test_settling_writes_one_restart_file_at_each_write_of_the_fluid(tmp_path):
    (c,) = commands(tmp_path, SETTLING)
    assert c.command(0.05) == "write_restart ../DEM/post/restart/liggghts.restartCFDEM"     # overwrite on
    assert c.when == "write" and c.due(7, 300, 1, True, 0.0, 1e-5, 100) and not c.due(8, 300, 1, False, 0.0, 1e-5, 100)


def test_write_liggghts_defaults_stamp_the_name_and_write_every_skips_writes(tmp_path):
    """Without Props: ../DEM/liggghts.restartCFDEM_<time %f> at every write; writeEvery 3: the
    1st, 4th, 7th write; writeLastOnly: the last coupling step only."""
    (c,) = commands(tmp_path, "liggghtsCommandModels ( runLiggghts writeLiggghts );\n")
    assert c.command(0.25) == "write_restart ../DEM/liggghts.restartCFDEM_0.250000"
    (c,) = commands(tmp_path, "liggghtsCommandModels ( runLiggghts writeLiggghts );\n"
                              "writeLiggghtsProps { overwrite on; writeEvery 3; }\n")
    assert [n for n in range(1, 9) if c.due(10 * n, 100, n, True, 0.0, 1e-5, 100)] == [1, 4, 7]
    (c,) = commands(tmp_path, "liggghtsCommandModels ( runLiggghts writeLiggghts );\n"
                              "writeLiggghtsProps { overwrite on; writeLastOnly on; }\n")
    assert [k for k in range(1, 101) if c.due(k, 100, 0, False, 0.0, 1e-5, 100)] == [100]


def test_an_interval_runs_from_the_floor_of_its_start_every_timeInterval_coupling_steps(tmp_path):
    """ErgunTestMPI's (commented out) executeProps2: startTime 0.04, endTime 100, timeInterval 40
    coupling steps of 50 x 1e-5 s: coupling steps 80, 120, 160, ...; the words dotdot, slash and
    timeStamp as CFDEM composes them."""
    (c,) = commands(tmp_path, """liggghtsCommandModels ( runLiggghts writeLiggghts execute );
writeLiggghtsProps { overwrite on; writeLastOnly on; }
executeProps2
{
    startTime 0.04; endTime 100; timeInterval 40;
    command ( write_restart noBlanks dotdot slash DEM slash post slash restart slash liggghts dot
              restartRareCFDEM_ timeStamp );
    runFirst off; runLast off; runEveryCouplingStep off; runEveryWriteStep off;
}
""", couple_every=50)[1:]
    assert c.command(0.04) == "write_restart ../DEM/post/restart/liggghts.restartRareCFDEM_0.040000"
    assert [k for k in range(1, 250) if c.due(k, 10**6, 0, False, 0.0, 1e-5, 50)] == [80, 120, 160, 200, 240]


def test_compose_numbers_labels_and_the_coupling_interval():
    assert compose(["fix", "f", "all", "move", "label", "number", "$couplingInterval"], [2.5], [7], 50) == \
        ("fix f all move 7 2.500000 50 ", False)
    assert compose(["a", "noBlanks", "b", "c", "blanks", "d"], [], [], 1) == ("a bc d ", False)    # (blanks: a blank at once)


@pytest.mark.parametrize("text, message", [
    ("liggghtsCommandModels ( runLiggghts setDEMGravity );", "setDEMGravity: the host runs runLiggghts"),
    ("liggghtsCommandModels ( execute );", "has no runLiggghts: CFDEM would not run the DEM"),
    ("liggghtsCommandModels ( runLiggghts execute );", "reads its command from executeProps1, which the file"),
    ("liggghtsCommandModels ( runLiggghts );\nrunLiggghtsProps { preNo false; runFirst on; }",
     "runFirst on: CFDEM runs the DEM at the first coupling step only"),
    ("liggghtsCommandModels ( runLiggghts writeLiggghts );\nwriteLiggghtsProps { writeLastOnly on; }",
     "overwrite: CFDEM needs on or off here"),
    ("liggghtsCommandModels ( runLiggghts execute );\nexecuteProps1 { command ( set number ); runFirst on; }",
     "asks for more 'number' or 'label' words than"),
    ("liggghtsCommandModels ( runLiggghts execute );\nexecuteProps1 { command ( run 100 ); runFirst on; }",
     "'run 100': steps run outside the coupling"),
    ("liggghtsCommandModels ( runLiggghts execute );\nexecuteProps1 { command ( unfix collheat_events ); runFirst on; }",
     "'unfix collheat_events': ids beginning with 'collheat_' are the host's own"),
    ("liggghtsCommandModels ( runLiggghts execute );\nexecuteProps1 { command ( print hi ); runFirst off; runLast off;"
     " runEveryCouplingStep off; runEveryWriteStep off; }", "needs startTime, endTime and timeInterval"),
])
def test_what_cfdem_or_the_host_would_not_run_is_refused_naming_it(tmp_path, text, message):
    with pytest.raises(CaseCommandsError, match="liggghtsCommands") as exc:
        commands(tmp_path, text)
    assert message in str(exc.value)


def test_write_times_follow_the_fluids_write_control():
    """runTime every 0.01 s from startTime 0.05: two in (0.055, 0.075]; timeStep every 4 steps of
    1 ms: one in (0.003, 0.005]; a wall-clock control cannot be followed."""
    assert write_times({"writeControl": "runTime", "writeInterval": 0.01}, 0.05, 0.055, 0.075) == 2
    assert write_times({"writeControl": "timeStep", "writeInterval": 4, "deltaT": 1e-3}, 0.0, 0.003, 0.005) == 1
    with pytest.raises(CaseCommandsError, match="clockTime"):
        write_times({"writeControl": "clockTime", "writeInterval": 1}, 0.0, 0.0, 1.0)
