"""Scene files: a valid one loads, every kind of mistake names the file and the key."""
import pytest

from pyhost.scene import SceneError, load_scene

VALID = """
[effects]
contact_heat = "A"

[materials.steel]
density = 7800.0
youngs_modulus = 210e9
poisson_ratio = 0.3
yield_stress = 300e6
heat_capacity = 470
conductivity = 45.0
dem = { youngs_modulus = 5e7, restitution = 0.9 }

[[particles]]
material = "steel"
count = 2
radius = 2e-3
temperature = 400.0
region = [0.0, 0.01, 0.0, 0.01, 0.0, 0.01]

[[walls]]
plane = "zlo"
material = "steel"
temperature = 300.0

[domain]
box = [0.0, 0.1, 0.0, 0.01, 0.0, 0.2]

[time]
dem_step = 1e-6
end = 0.01
"""


def write(tmp_path, text):
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_valid_scene_loads_with_defaults(tmp_path):
    s = load_scene(write(tmp_path, VALID))
    assert s.materials["steel"].heat_capacity == 470.0          # int accepted as float
    assert s.materials["steel"].dem.friction == 0.3             # default
    assert s.time.sample_every == 1 and s.fluid is None
    effects = s.effects_summary()
    assert effects == dict(fluid_solver=False, convection=False, conduction=False, particle_temperatures=True,
                           contact_extraction=True, collision_heat=True,
                           restitution_feedback=False, enduring_conduction=False, wall_heat=True)


def test_dry_isothermal_scene_builds_nothing_extra(tmp_path):
    s = load_scene(write(tmp_path, VALID.replace('contact_heat = "A"', 'contact_heat = "none"')))
    summary = s.effects_summary()
    assert not summary["fluid_solver"] and not summary["contact_extraction"] and not summary["wall_heat"]


@pytest.mark.parametrize("old,new,message", [
    ("count = 2", "count = 2\ncolour = 3", "particles[0].colour: unknown key"),
    ("density = 7800.0", "density = -1.0", "materials.steel.density: must be > 0"),
    ("radius = 2e-3", 'radius = "big"', "particles[0].radius: must be float"),
    ("count = 2", "count = 2.5", "particles[0].count: must be int"),
    ('contact_heat = "A"', 'contact_heat = "D"', "effects.contact_heat: must be one of none, A, B, C, hertz, softened"),
    ('contact_heat = "A"', 'contact_heat = ["A", "D"]', "effects.contact_heat: must be one of A, B, C, hertz"),
    ('contact_heat = "A"', 'contact_heat = []', "effects.contact_heat: must be one of"),
    ('contact_heat = "A"', 'contact_heat = ["A", "softened", "A"]', "effects.contact_heat: names a model twice"),
    ('contact_heat = "A"', 'contact_heat = ["softened", "A"]\nrestitution_feedback = true',
     "effects.restitution_feedback: needs a contact model (A, B, C) first"),
    ('material = "steel"\ncount', 'material = "glass"\ncount', "particles[0].material: unknown material"),
    ("restitution = 0.9", "restitution = 1.5", "materials.steel.dem.restitution"),
    ("end = 0.01", "end = 1e-7", "time.dem_step: must be below time.end"),
    ("[domain]", "[domian]", "domian: unknown section"),
    ("box = [0.0, 0.1,", "box = [0.2, 0.1,", "domain.box: each min must be below its max"),
    ("yield_stress = 300e6\n", "", "materials.steel.yield_stress: missing"),
    ("[effects]", "[effects]\nfluid = true", "fluid: missing section"),
    ('contact_heat = "A"', 'contact_heat = "A"\nconvection = "wakao"',
     "effects.convection: must be one of none, deen, gunn, li_mason, ranz_marshall"),
    ('contact_heat = "A"', 'contact_heat = "A"\nconvection = "gunn"', "effects.convection: needs the gas"),
    ("[domain]", "[fluid]\nconductivity = 0.0\n\n[domain]", "fluid.conductivity: must be > 0"),
    ("[domain]", "[fluid]\nheat_capacity = -5.0\n\n[domain]", "fluid.heat_capacity: must be > 0"),
    ("dem_step = 1e-6", "dem_step = nan", "time.dem_step: must be finite"),
    ('contact_heat = "A"', 'contact_heat = "A"\ncontact_conduction = "zhou"',
     "effects.contact_conduction: must be one of none, lethe, lethe_rough, mfix, morris, got 'zhou'"),
    ('contact_heat = "A"', 'contact_heat = "A"\ngap_conduction = "bob"',
     "effects.gap_conduction: must be one of none, lethe, rong_horio, got 'bob'"),
    ('contact_heat = "A"', 'contact_heat = "A"\ncontact_conduction = "mfix"\nenduring_conduction = true',
     "effects.contact_conduction: 'mfix' and effects.enduring_conduction both conduct"),
    ('contact_heat = "A"', 'contact_heat = "A"\ngap_conduction = "rong_horio"',
     "conduction.gas_conductivity: missing (effects.gap_conduction = 'rong_horio'"),
    ('contact_heat = "A"', 'contact_heat = "A"\ngap_conduction = "lethe"\n[conduction]\ngas_conductivity = 0.026',
     "conduction.gas_parameter: must be > 0 with effects.gap_conduction"),
    ("[domain]", "[conduction]\nlens = 0.0\n\n[domain]", "conduction.lens: must be > 0"),
    ("[domain]", "[conduction]\nevery = 0\n\n[domain]", "conduction.every: must be > 0"),
    ("[domain]", "[conduction]\nreach = 1.0\n\n[domain]", "conduction.reach: unknown key; known: every"),
])
def test_mistakes_name_file_and_key(tmp_path, old, new, message):
    assert old in VALID
    path = write(tmp_path, VALID.replace(old, new, 1))
    with pytest.raises(SceneError) as err:
        load_scene(path)
    assert str(path) in str(err.value) and message in str(err.value)


def test_missing_file_and_broken_toml(tmp_path):
    with pytest.raises(SceneError, match="no such scene file"):
        load_scene(tmp_path / "nope.toml")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(write(tmp_path, "[effects\n"))


FLUID = "\n[fluid]\ninlet_table = [[0.0, 0.0], [0.1, 0.0], [0.11, 0.5]]\n"


def test_inlet_table_is_piecewise_linear_and_held(tmp_path):
    s = load_scene(write(tmp_path, VALID + FLUID))
    assert s.fluid.inlet_at(0.05) == 0.0
    assert s.fluid.inlet_at(0.105) == pytest.approx(0.25, rel=1e-12)
    assert s.fluid.inlet_at(1.0) == 0.5
    plain = load_scene(write(tmp_path, VALID + "\n[fluid]\ninlet_velocity = 1.5\n"))
    assert plain.fluid.inlet_at(0.3) == 1.5


@pytest.mark.parametrize("table,message", [
    ("[[0.0, 0.0], [0.0, 0.5]]", "times must increase"),
    ("[[0.0, -0.1]]", "must be >= 0"),
    ("[[0.0, 0.0, 1.0]]", "must be 2 numbers"),
    ("[0.0, 0.1]", "each row must be [time, velocity]"),
])
def test_bad_inlet_table_names_the_key(tmp_path, table, message):
    path = write(tmp_path, VALID + f"\n[fluid]\ninlet_table = {table}\n")
    with pytest.raises(SceneError) as err:
        load_scene(path)
    assert "fluid.inlet_table" in str(err.value) and message in str(err.value)


def test_inlet_table_and_velocity_exclude_each_other(tmp_path):
    with pytest.raises(SceneError, match="either inlet_table or inlet_velocity"):
        load_scene(write(tmp_path, VALID + FLUID.replace("[fluid]", "[fluid]\ninlet_velocity = 1.0")))


def test_a_variable_name_liggghts_cannot_take_is_refused(tmp_path):
    """dem.test_variables = { "n fill" = 5 }: LIGGGHTS' -var would end the process with an empty
    message; refused when the scene is read, naming the key."""
    (tmp_path / "in.x").write_text("run 10\n")
    (tmp_path / "case.toml").write_text('[dem]\nscript = "in.x"\ntest_variables = { "n fill" = 5 }\n'
                                        '[materials.m]\ntypes = [1]\ndensity = 1.0\nyoungs_modulus = 1.0\n'
                                        'poisson_ratio = 0.3\nyield_stress = 1.0\nheat_capacity = 1.0\n'
                                        'conductivity = 1.0\n')
    with pytest.raises(SceneError, match=r"dem.test_variables: 'n fill' is not a LIGGGHTS variable name"):
        load_scene(tmp_path / "case.toml")


@pytest.mark.parametrize("files, where, words", [
    (["CFD/constant/couplingProperties", "DEM/in.liggghts_init", "DEM/in.liggghts_run"], ".",
     ["is a CFDEM tutorial: its case.toml goes into CFD/"]),
    (["CFD/constant/couplingProperties", "DEM/in.liggghts_init", "DEM/in.liggghts_run"], "CFD",
     ["is a CFDEM case's OpenFOAM folder", "fluid = true", 'case = "."', "the one its couplingProperties names"]),
    (["constant/kinematicCloudProperties", "system/controlDict"], ".", ["python -m pyhost dpmfoam"]),
    (["in.packing", "post/x"], ".", ['holds the LIGGGHTS script in.packing', 'script = "in.packing"']),
    (["notes.txt"], ".", []),
])
def test_a_missing_scene_file_says_what_the_folder_is(tmp_path, files, where, words):
    """'python -m pyhost run FOLDER' on a tutorial as it is (no case.toml yet): the error names
    what the folder holds and how it becomes a case of the host."""
    for f in files:
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / f).write_text("")
    with pytest.raises(SceneError) as err:
        load_scene(tmp_path / where / "case.toml")
    message = str(err.value)
    assert message.startswith(f"{tmp_path / where / 'case.toml'}: no such scene file")
    assert all(w in message for w in words) and (words or message.endswith("no such scene file")), message


def test_conduction_is_built_only_when_asked_and_takes_the_fluid_gas(tmp_path):
    """A scene without a conduction model builds none (and neither needs nor reads [conduction]);
    a gap model takes the [fluid]'s gas conductivity when [conduction] gives none."""
    plain = load_scene(write(tmp_path, VALID))
    assert not plain.effects_summary()["conduction"]
    gas = load_scene(write(tmp_path, VALID.replace('contact_heat = "A"', 'contact_heat = "none"\ngap_conduction = '
                                                   '"rong_horio"').replace("[domain]", "[fluid]\nconductivity = 0.03"
                                                                           "\n\n[domain]")))
    assert gas.effects_summary()["conduction"] and gas.effects_summary()["particle_temperatures"]
    assert gas.conduction.gas_conductivity == 0.03


def test_a_conduction_mistake_stops_the_run_with_exit_2(tmp_path):
    import subprocess
    import sys
    path = write(tmp_path, VALID.replace('contact_heat = "A"', 'contact_heat = "A"\ncontact_conduction = "zhou"'))
    r = subprocess.run([sys.executable, "-m", "pyhost", "run", str(tmp_path), "--out", str(tmp_path / "out")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert str(path) in r.stderr and "effects.contact_conduction: must be one of none, lethe, lethe_rough, mfix, morris" in r.stderr
