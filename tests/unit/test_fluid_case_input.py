"""A user's OpenFOAM case as CFDEM keeps it: the gas density from transportProperties or a
uniform 0/rho, else a refusal naming the file (exit 2), before any engine starts."""
import numpy as np
import pytest
from conftest import cfdem_case_toml
from foamlib import FoamFile

from pyhost.engines.fluid_case import box_case, case_density

WALLS = {f: "wall" for f in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi")}


@pytest.fixture
def case(tmp_path):
    folder = box_case(tmp_path / "fluid", lo=(0, 0, 0), hi=(1, 1, 1), cells=(1, 1, 1), boundaries=WALLS,
                      rho=1.5, nu=1e-5)
    return folder


def rho_field(case, value):
    f = FoamFile(case / "0" / "rho")
    f.class_, f.object_ = "volScalarField", "rho"
    f.update({"dimensions": FoamFile.DimensionSet(mass=1, length=-3), "internalField": value,
              "boundaryField": {".*": {"type": "zeroGradient"}}})


def test_density_from_transport_properties(case):
    assert case_density(case) == (1.5, "constant/transportProperties: rho")


def test_density_from_0_rho_when_transport_properties_has_none(case):
    del FoamFile(case / "constant" / "transportProperties")["rho"]
    rho_field(case, 10.0)
    assert case_density(case) == (10.0, "0/rho: internalField")


def test_no_density_anywhere_names_both_places(case):
    del FoamFile(case / "constant" / "transportProperties")["rho"]
    with pytest.raises(ValueError, match=r"transportProperties has no rho and there is no 0/rho"):
        case_density(case)


def test_non_uniform_0_rho_is_refused(case):
    del FoamFile(case / "constant" / "transportProperties")["rho"]
    rho_field(case, np.array([1.0]))
    with pytest.raises(ValueError, match=r"0/rho: internalField: the gas density must be one uniform"):
        case_density(case)


def test_copy_of_a_case_holding_runs_leaves_them_out(case):
    """case = ".": the copy (OUT/fluid inside the case) holds the case's own files only: not
    itself, not an earlier run's output written with another --out (scene.json), not the
    solver's later times or processor folders."""
    import shutil

    from pyhost.world import _case_copy_filter
    (case / "case.toml").write_text("")
    for old in ("old-run", "output"):
        (case / old / "fluid").mkdir(parents=True)
        (case / old / "scene.json").write_text("{}")
    (case / "0.5").mkdir()
    (case / "processor0").mkdir()
    copy = case / "output" / "fluid"
    shutil.rmtree(copy)
    shutil.copytree(case, copy, ignore=_case_copy_filter(copy, case))
    assert sorted(p.name for p in copy.iterdir()) == ["0", "case.toml", "constant", "system"]


def test_a_case_starting_later_starts_from_its_time_folder_and_the_copy_keeps_it(case):
    """startFrom startTime at 0.05 s (ErgunTestMPI_restart's second stage): the case's folder of
    that time is the start, kept in the copy where other times are left out; latestTime takes
    the latest folder; without a folder of that time, the case has none (None)."""
    import shutil

    from pyhost.engines.fluid_case import start_time
    from pyhost.world import _case_copy_filter
    def control(key, value):                # (a FoamFile each time: one kept across writes duplicated an entry)
        FoamFile(case / "system" / "controlDict")[key] = value

    control("startTime", 0.05)
    assert start_time(case) == (0.05, None)
    for t in ("0.05", "0.1"):
        shutil.copytree(case / "0", case / t)
    assert start_time(case) == (0.05, "0.05")
    control("startFrom", "latestTime")
    assert start_time(case) == (0.1, "0.1")
    control("startFrom", "startTime")
    copy = case.parent / "copy"
    shutil.copytree(case, copy, ignore=_case_copy_filter(copy, case, start_time(case)[1]))
    assert sorted(p.name for p in copy.iterdir()) == ["0", "0.05", "constant", "system"]


def test_a_start_time_without_its_folder_is_refused_naming_what_to_copy(case):
    """A second stage whose fluid state a run of the host wrote into its own output: exit 2
    before any engine, with the cp to make (the host writes no time into the user's case)."""
    from pyhost.engines.foam_case_check import check_start
    from pyhost.schema import SceneError
    FoamFile(case / "system" / "controlDict")["startTime"] = 0.05
    with pytest.raises(SceneError, match="has no time folder of that time: give the case the fluid's fields"):
        check_start(case, "case.toml")
    (case / "output" / "fluid" / "0.05").mkdir(parents=True)
    (case / "output" / "scene.json").write_text("{}")
    with pytest.raises(SceneError, match=r"starts at t = 0.05 s.*a run of the host wrote it in .*output/fluid/0.05: "
                                         r"copy it into the case \(cp -r "):
        check_start(case, "case.toml")


def piso_case(case, application, pimple=None):
    f = FoamFile(case / "system" / "fvSolution")
    del f["PIMPLE"]
    f["PISO"] = {"nCorrectors": 4, "nNonOrthogonalCorrectors": 1, "pRefCell": 0, "pRefValue": 0}
    if pimple is not None:
        f["PIMPLE"] = pimple
    FoamFile(case / "system" / "controlDict")["application"] = application


@pytest.mark.parametrize("application, pimple", [("cfdemSolverPiso", {"nOuterCorrectors": 1}),
                                                 ("cfdemSolverPisoScalar", None), ("collheatFoam", None)])
def test_a_piso_solvers_settings_run_as_pimple(case, application, pimple):
    """CFDEM's solvers read PISO (ErgunTestMPI: 4 correctors, 1 non-orthogonal corrector on its
    O-grid; collheatFoam ran PIMPLE's defaults, 1 and 0, and its bed's pressure drop was 6 %
    below the drag law's, 0.05 % with them). PIMPLE becomes PISO's entries, one outer loop."""
    from pyhost.engines.fluid_case import adopt_piso

    piso_case(case, application, pimple)
    assert adopt_piso(case)
    loop = dict(FoamFile(case / "system" / "fvSolution")["PIMPLE"])
    assert loop == {"nCorrectors": 4, "nNonOrthogonalCorrectors": 1, "pRefCell": 0, "pRefValue": 0,
                    "nOuterCorrectors": 1}


def test_a_pimple_solvers_own_pimple_stays(case):
    from pyhost.engines.fluid_case import adopt_piso

    piso_case(case, "cfdemSolverPimple", {"nOuterCorrectors": 3, "nCorrectors": 2})
    assert not adopt_piso(case)
    assert dict(FoamFile(case / "system" / "fvSolution")["PIMPLE"]) == {"nOuterCorrectors": 3, "nCorrectors": 2}



# -- a CFDEM case's own settings: couplingProperties' drag and void fraction, the script's couple_every --

COUPLING = """FoamFile {{ version 2.0; format ascii; class dictionary; object couplingProperties; }}
modelType "A";
voidFractionModel {void};
forceModels
(
    gradPForce
    {drag}
    Archimedes
    {heat}
);
{props}
"""



def cfdem_layout(root, fluid="", time="", drag="KochHillDrag", void="divided", every=100, heat="", props="",
                 effects=""):
    """CFD/ (an OpenFOAM case with CFDEM's couplingProperties, case.toml in it) and DEM/ (a
    script whose CFDEM coupling fix couples every ``every`` steps); returns case.toml. ``heat``:
    a heat transfer force model, ``props``: its dictionary; ``effects``: lines of [effects]."""
    cfd = box_case(root / "CFD", lo=(0, 0, 0), hi=(1, 1, 1), cells=(1, 1, 1), boundaries=WALLS, rho=1.5, nu=1e-5,
                   T0=300.0)
    (cfd / "constant" / "couplingProperties").write_text(COUPLING.format(void=void, drag=drag, heat=heat,
                                                                         props=props))
    (root / "DEM").mkdir()
    (root / "DEM" / "in.liggghts_run").write_text(
        f"units si\nfix cfd all couple/cfd couple_every {every} mpi   # CFDEM's coupling\nrun 1\n")
    (cfd / "case.toml").write_text(cfdem_case_toml(fluid=fluid, time=time).replace("fluid = true\n",
                                                                                    "fluid = true\n" + effects))
    return cfd / "case.toml"


def test_a_cfdem_cases_drag_void_fraction_and_coupling_are_taken(tmp_path):
    """Without fluid.drag, fluid.void_fraction and time.couple_every the scene takes the case's
    KochHillDrag and divided and the script's couple_every 100 (the defaults are gidaspow,
    centre and 50: a CFDEM user's case ran with another drag law, silently); given and equal,
    they stand."""
    from pyhost.scene import load_scene

    scene = load_scene(cfdem_layout(tmp_path / "a"))
    assert (scene.fluid.drag, scene.fluid.void_fraction, scene.time.couple_every) == ("koch_hill", "divided", 100)
    scene = load_scene(cfdem_layout(tmp_path / "b", fluid='drag = "difelice"\nvoid_fraction = "centre"\n',
                                    time="couple_every = 20\n", drag="DiFeliceDrag", void="centre", every=20))
    assert (scene.fluid.drag, scene.fluid.void_fraction, scene.time.couple_every) == ("difelice", "centre", 20)


@pytest.mark.parametrize("kwargs, message", [
    (dict(fluid='drag = "gidaspow"\n'), r"fluid.drag: 'gidaspow', but .*couplingProperties forceModels has "
                                        r"KochHillDrag \('koch_hill'\): remove fluid.drag"),
    (dict(fluid='void_fraction = "centre"\n'), r"fluid.void_fraction: 'centre', but .*voidFractionModel has divided"),
    (dict(drag="BeetstraDrag"), r"fluid.drag: .*forceModels has BeetstraDrag, which the host does not have \(it "
                                r"has KochHillDrag as 'koch_hill'.*give fluid.drag to choose"),
    (dict(void="trilinear"), r"fluid.void_fraction: .*voidFractionModel has trilinear, which the host does not have"),
    (dict(time="couple_every = 50\n"), r"time.couple_every: 50, but .*in.liggghts_run:2 couples every 100 DEM "
                                       r"steps \(fix couple/cfd\)"),
])
def test_a_scene_that_disagrees_with_its_cfdem_case_is_refused(tmp_path, kwargs, message):
    from pyhost.scene import SceneError, load_scene

    with pytest.raises(SceneError, match=message):
        load_scene(cfdem_layout(tmp_path, **kwargs))


def test_a_model_the_host_lacks_runs_with_the_scenes_choice(tmp_path):
    from pyhost.scene import load_scene

    scene = load_scene(cfdem_layout(tmp_path, fluid='drag = "wenyu"\nvoid_fraction = "centre"\n',
                                    drag="BeetstraDrag", void="trilinear"))
    assert (scene.fluid.drag, scene.fluid.void_fraction) == ("wenyu", "centre")


def test_a_cfdem_cases_coupling_interval_is_its_couplingInterval(tmp_path):
    """With CFDEM's in-memory exchange (twoWayMPI, every tutorial's) CFDEM runs the DEM
    couplingInterval steps per coupling, whatever the script's couple_every (LIGGGHTS says it
    is overridden): ErgunTestMPI 50 where its script says 100, packedBedTemp 500 where it
    says 100; the host took the script's. With a file exchange the script's stands."""
    from pyhost.scene import SceneError, load_scene

    mpi = "dataExchangeModel twoWayMPI;\ncouplingInterval 50;"
    assert load_scene(cfdem_layout(tmp_path / "a", props=mpi)).time.couple_every == 50
    assert load_scene(cfdem_layout(tmp_path / "b", props=mpi, time="couple_every = 50\n")).time.couple_every == 50
    files = "dataExchangeModel twoWayFiles;\ncouplingInterval 50;"
    assert load_scene(cfdem_layout(tmp_path / "c", props=files)).time.couple_every == 100
    with pytest.raises(SceneError, match=r"time.couple_every: 100, but .*couplingProperties couplingInterval has 50 "
                                         r"\(50\): remove time.couple_every"):
        load_scene(cfdem_layout(tmp_path / "d", props=mpi, time="couple_every = 100\n"))


def test_a_cfdem_cases_ddt_voidfraction_is_taken(tmp_path):
    """CFDEM's solvers leave d(alpha)/dt out of the continuity equation unless
    useDDTvoidfraction says b (or a); every tutorial but one keeps the default off, and the
    host solved it in: a packed bed's jiggling beads then drove the gas, its pressure drop
    scattering by 10 % from write to write (ErgunTestMPI). Taken for fluid.ddt_alpha; "a"
    (the particles' flux divergence) the host does not have."""
    from pyhost.scene import SceneError, load_scene

    assert load_scene(cfdem_layout(tmp_path / "a")).fluid.ddt_alpha is False
    assert load_scene(cfdem_layout(tmp_path / "b", props="useDDTvoidfraction b;")).fluid.ddt_alpha is True
    assert load_scene(cfdem_layout(tmp_path / "c", props="useDDTvoidfraction off;")).fluid.ddt_alpha is False
    with pytest.raises(SceneError, match=r"fluid.ddt_alpha: True, but .*couplingProperties has no useDDTvoidfraction: "
                                         r"CFDEM's default off \(False\): remove fluid.ddt_alpha"):
        load_scene(cfdem_layout(tmp_path / "d", fluid="ddt_alpha = true\n"))
    with pytest.raises(SceneError, match=r"fluid.ddt_alpha: .*useDDTvoidfraction has a, which the host does not have "
                                         r"\(it has off as False, b as True\)"):
        load_scene(cfdem_layout(tmp_path / "e", props="useDDTvoidfraction a;"))


def test_a_cfdem_cases_fluid_fraction_floor_is_taken(tmp_path):
    """CFDEM's divided and centre models clip the fluid fraction at their Props' alphaMin
    (packedBedTemp 0.4, ErgunTestMPI_restart 0.01), 0.1 without it (ErgunTestMPI): taken for
    fluid.alpha_min, whose scene default 0.3 ran in their place, silently; a scene value that
    differs is refused."""
    from pyhost.scene import SceneError, load_scene

    assert load_scene(cfdem_layout(tmp_path / "a")).fluid.alpha_min == 0.1
    assert load_scene(cfdem_layout(tmp_path / "b", props="dividedProps { alphaMin 0.4; }")).fluid.alpha_min == 0.4
    assert load_scene(cfdem_layout(tmp_path / "c", void="centre", fluid='void_fraction = "centre"\nalpha_min = 0.01\n',
                                   props="centreProps { alphaMin 0.01; }")).fluid.alpha_min == 0.01
    with pytest.raises(SceneError, match=r"fluid.alpha_min: 0.3, but .*couplingProperties dividedProps alphaMin has "
                                         r"0.4 \(0.4\): remove fluid.alpha_min"):
        load_scene(cfdem_layout(tmp_path / "d", fluid="alpha_min = 0.3\n", props="dividedProps { alphaMin 0.4; }"))
    with pytest.raises(SceneError, match=r"fluid.alpha_min: 0.3, but .*dividedProps has no alphaMin: CFDEM's default "
                                         r"0.1 \(0.1\)"):
        load_scene(cfdem_layout(tmp_path / "e", fluid="alpha_min = 0.3\n"))


LAEU = "LaEuScalarTempProps { tempFieldName \"T\"; partTempName \"Temp\"; lambda 0.0256; Cp 1007; %s }"
GENERAL = "scalarGeneralExchangeProps { tempFieldName \"T\"; lambda 0.03; %s }"


@pytest.mark.parametrize("heat, props, expected", [
    ("LaEuScalarTemp", LAEU % "", ("li_mason", 0.0256, 1007.0)),              # CFDEM's default: LiMason
    ("LaEuScalarTemp", LAEU % "NuCorrelation Gunn;", ("gunn", 0.0256, 1007.0)),
    ("scalarGeneralExchange", GENERAL % "useLiMason true;", ("li_mason", 0.03, 1005.0)),
    ("scalarGeneralExchange", GENERAL % "", ("deen", 0.03, 1005.0)),         # its default: Deen et al.
])
def test_a_cfdem_cases_heat_transfer_is_taken(tmp_path, heat, props, expected):
    """The case's gas-particle heat transfer model (LaEuScalarTemp's NuCorrelation, CFDEM's
    default LiMason; scalarGeneralExchange's switches, default Deen) and the gas conductivity
    and heat capacity it names: taken without effects.convection, fluid.conductivity and
    fluid.heat_capacity, where the run used to go without any gas-particle heat (convection
    'none'), silently; the heat capacity the model does not name stays the scene's 1005."""
    from pyhost.scene import load_scene

    scene = load_scene(cfdem_layout(tmp_path, heat=heat, props=props))
    assert (scene.effects.convection, scene.fluid.conductivity, scene.fluid.heat_capacity) == expected


@pytest.mark.parametrize("kwargs, message", [
    (dict(effects='convection = "gunn"\n'), r"effects.convection: 'gunn', but .*couplingProperties forceModels has "
                                             r"LaEuScalarTemp \(LiMason\) \('li_mason'\): remove effects.convection"),
    (dict(effects='convection = "none"\n'), r"effects.convection: 'none', but .* LaEuScalarTemp \(LiMason\)"),
    (dict(fluid="conductivity = 0.026\n"), r"fluid.conductivity: 0.026, but .*LaEuScalarTempProps lambda has 0.0256"),
    (dict(props=GENERAL % "useGeneralCorrelation true;", heat="scalarGeneralExchange"),
     r"effects.convection: .* has scalarGeneralExchange \(generalCorrelation\), which the host does not have \(it "
     r"has LiMason as 'li_mason', Gunn as 'gunn', Deen as 'deen'\): give effects.convection to choose"),
])
def test_a_scene_that_disagrees_with_its_cfdem_cases_heat_transfer_is_refused(tmp_path, kwargs, message):
    from pyhost.scene import SceneError, load_scene

    kwargs = {"heat": "LaEuScalarTemp", "props": LAEU % "", **kwargs}
    with pytest.raises(SceneError, match=message):
        load_scene(cfdem_layout(tmp_path, **kwargs))


def test_a_cfdem_case_with_species_is_refused(tmp_path):
    """CFDEM's cfdemSolverPisoSTM/packedBedTemp transports a species C with the particles'
    speciesC: the host solves no species, and the run ended with exit 0, C never moved."""
    from pyhost.scene import SceneError, load_scene

    toml = cfdem_layout(tmp_path, heat="scalarGeneralExchange",
                        props=GENERAL % "useLiMason true; partSpeciesNames ( speciesC ); partSpeciesFluxNames "
                                        "( speciesCFlux );")
    with pytest.raises(SceneError, match=r"fluid.case: the case transports species \(speciesC: .*couplingProperties "
                                         r"scalarGeneralExchangeProps partSpeciesNames\); the host solves the gas "
                                         r"flow and temperature only"):
        load_scene(toml)
    (tmp_path / "CFD" / "constant" / "scalarTransportProperties").write_text(
        "FoamFile { version 2.0; format ascii; class dictionary; object scalarTransportProperties; }\n"
        "scalarTransportModel generalManual;\ngeneralManualProps { eulerianFields ( C T ); }\n")
    with pytest.raises(SceneError, match=r"species \(C, speciesC: .*scalarTransportProperties generalManualProps "
                                         r"eulerianFields\)"):
        load_scene(toml)


@pytest.mark.parametrize("kwargs, where", [
    (dict(void="IB", drag="ShirgaonkarIB"), "voidFractionModel IB"),
    (dict(void="bigParticle", drag=""), "voidFractionModel bigParticle"),
    (dict(drag="ShirgaonkarIB"), "forceModels ShirgaonkarIB"),
])
def test_a_cfdem_case_of_resolved_particles_is_refused(tmp_path, kwargs, where):
    """cfdemSolverIB's twoSpheresGlowinskiMPI resolves its two spheres on the mesh (immersed
    boundaries): refused as such, where the host used to advise choosing one of its own void
    fraction models (which would have run it as unresolved particles)."""
    from pyhost.scene import SceneError, load_scene

    with pytest.raises(SceneError, match=r"fluid.case: the case resolves its particles on the mesh \(an immersed "
                                         rf"boundary, as cfdemSolverIB: .*couplingProperties {where}\)"):
        load_scene(cfdem_layout(tmp_path, **kwargs))


def test_a_cfdem_case_whose_flow_is_not_solved_is_refused(tmp_path):
    """voidfractionTest says solveFlow off (CFDEM keeps the gas still and computes the fraction
    and the forces only): the host, which always solves the flow, ran it as a moving gas."""
    from pyhost.scene import SceneError, load_scene

    with pytest.raises(SceneError, match=r"fluid.case: .*couplingProperties solveFlow off: the case keeps its gas "
                                         r"still .*the host always solves the gas flow"):
        load_scene(cfdem_layout(tmp_path, props="solveFlow off;"))


@pytest.mark.parametrize("props, extra, message", [
    ("", "MeiLift", "forceModels MeiLift: a force the host does not have"),
    ("", "virtualMassForce fieldStore", "forceModels virtualMassForce: a force the host does not have"),
    ("smoothingModel constDiffSmoothing;", "", "smoothingModel constDiffSmoothing: CFDEM smooths the exchange"),
])
def test_a_cfdem_case_with_a_force_or_smoothing_the_host_has_not_is_refused(tmp_path, props, extra, message):
    """CFDEM's lift and virtual mass forces, or its smoothing of the exchange fields, change the
    answer, and the host has none of them: refused naming the entry, where the host ran without
    them and ended with exit 0. The tutorials' own lists (drag, Archimedes, gradPForce,
    viscForce, fieldStore, the heat models; smoothingModel off) pass."""
    from pyhost.scene import SceneError, load_scene

    with pytest.raises(SceneError, match=rf"fluid.case: .*couplingProperties {message}"):
        load_scene(cfdem_layout(tmp_path / "bad", drag="KochHillDrag " + extra, props=props))
    load_scene(cfdem_layout(tmp_path / "good", drag="KochHillDrag viscForce fieldStore", props="smoothingModel off;"))


def test_mean_velocity_forces_run_as_collheatfoams(case):
    """CFDEM's meanSupVelocityForce (its Coeffs sub-dictionary, its own keys) and OpenFOAM's
    meanVelocityForce become collheatMeanVelocityForce in the copy, superficial for CFDEM's;
    other fvOptions are left as they are."""
    from pyhost.engines.fluid_case import adopt_mean_velocity_force

    (case / "system" / "fvOptions").write_text(
        "FoamFile { version 2.0; format ascii; class dictionary; object fvOptions; }\n"
        "drive { type meanSupVelocityForce; active yes; meanSupVelocityForceCoeffs { selectionMode all; "
        "fields (U); Ubar (10 0 0); relaxation 0.9; twoPhase false; coupled true; voidfractionField voidfraction; } }\n"
        "plain { type meanVelocityForce; selectionMode all; fields (U); Ubar (0 1 0); }\n"
        "heat { type scalarSemiImplicitSource; selectionMode all; }\n")
    assert adopt_mean_velocity_force(case) == ["drive (meanSupVelocityForce)", "plain (meanVelocityForce)"]
    f = FoamFile(case / "system" / "fvOptions")
    drive, plain = dict(f["drive"]), dict(f["plain"])
    assert drive["type"] == plain["type"] == "collheatMeanVelocityForce"
    assert drive["superficial"] is True and plain["superficial"] is False
    assert list(drive["Ubar"]) == [10, 0, 0] and drive["relaxation"] == 0.9 and drive["fields"] == ["U"]
    assert not {"meanSupVelocityForceCoeffs", "twoPhase", "coupled", "voidfractionField"} & set(drive)
    assert f["heat"]["type"] == "scalarSemiImplicitSource"
