"""Write a small OpenFOAM case for ``collheatFoam``: a box of uniform hexahedra.

Files are written with foamlib; every value comes from the arguments (SI units). Each of
the six faces (xlo, xhi, ylo, yhi, zlo, zhi) gets one boundary kind:

- ``"wall"``: no-slip wall; ``"slip"``: frictionless wall (both: fixedFluxPressure);
- ``("inlet", (ux, uy, uz))``: fixed velocity (m/s), fixedFluxPressure;
- ``("inlet_table", [(t, (ux, uy, uz)), ...])``: velocity (m/s) piecewise linear in time t
  (s), held after the last row (OpenFOAM's uniformFixedValue table), fixedFluxPressure;
- ``"outlet"``: fixed pressure 0, velocity zeroGradient (inletOutlet).

With a gas temperature (``T0``) the case also gets 0/T for ``collheatFoam -energy``: inlets
at ``T_inlet``, outlets zeroGradient (T0 for backflow), walls adiabatic unless
``T_walls`` gives a face its fixed temperature (K); Cp and kappa go to transportProperties.
"""
from __future__ import annotations

import gzip
import math
import re
import shutil
from pathlib import Path

import numpy as np
from foamlib import FoamFile

FACES = {  # blockMesh vertex order of a hex: 0..3 bottom (z lo), 4..7 top
    "xlo": (0, 4, 7, 3), "xhi": (1, 2, 6, 5), "ylo": (0, 1, 5, 4),
    "yhi": (3, 7, 6, 2), "zlo": (0, 3, 2, 1), "zhi": (4, 5, 6, 7),
}


def _dict(path: Path, class_: str = "dictionary") -> FoamFile:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.unlink(missing_ok=True)
    f = FoamFile(path)
    f.class_ = class_
    f.object_ = path.name
    return f


def _text(path: Path) -> str | None:
    return path.read_text() if path.is_file() else None


def _bc(kind, field: str) -> dict:
    name, value = (kind if isinstance(kind, tuple) else (kind, None))
    if name not in ("wall", "slip", "inlet", "inlet_table", "outlet"):
        raise ValueError(f"unknown boundary kind '{name}'; choices: wall, slip, inlet, inlet_table, outlet")
    if field == "T":
        return _temperature_bc(name, value)
    if field == "U" and name == "inlet_table":
        rows = [[float(t), [float(c) for c in u]] for t, u in value]
        return {"type": "uniformFixedValue", "uniformValue": ("table", rows), "value": np.array(rows[0][1])}
    if field == "U":
        return {"wall": {"type": "noSlip"}, "slip": {"type": "slip"},
                "inlet": {"type": "fixedValue", "value": np.asarray(value, float)},
                "outlet": {"type": "inletOutlet", "inletValue": np.zeros(3),
                           "value": np.zeros(3)}}[name]
    if name == "outlet":
        return {"type": "fixedValue", "value": 0.0}
    return {"type": "fixedFluxPressure", "value": 0.0}


def _temperature_bc(name, value) -> dict:
    """0/T of a face: ``value`` is (T0, T_inlet, T_wall or None) in K."""
    T0, T_inlet, T_wall = value
    if name in ("inlet", "inlet_table"):
        return {"type": "fixedValue", "value": float(T_inlet)}
    if name == "outlet":
        return {"type": "inletOutlet", "inletValue": float(T0), "value": float(T0)}
    return {"type": "zeroGradient"} if T_wall is None else {"type": "fixedValue", "value": float(T_wall)}


def split_of(cells, nprocs: int) -> list[int]:
    """Subdomains along x, y, z of a box mesh on ``nprocs`` ranks: slabs across the horizontal
    axis with more cells (a bed's particles sit low, so slabs along z would leave the upper
    ranks idle)."""
    axis = 0 if cells[0] >= cells[1] else 1
    return [nprocs if a == axis else 1 for a in range(3)]


def box_case(path: str | Path, *, lo, hi, cells, boundaries: dict, rho: float, nu: float,
             gravity=(0.0, 0.0, -9.81), dt: float = 1e-3, nprocs: int = 1,
             n_correctors: int = 2, n_outer: int = 1, max_speed: float = 1e3,
             rel_tol: float = 0.01, T0: float | None = None, cp: float = 1005.0, kappa: float = 0.026,
             T_inlet: float | None = None, T_walls: dict | None = None) -> Path:
    """Write the case at ``path`` and return it. ``lo``, ``hi``: box corners (m);
    ``cells``: cells per axis; ``boundaries``: kind per face (module doc); ``rho`` (kg/m^3),
    ``nu`` (m^2/s): fluid; ``dt``: default time step (s); ``nprocs``: ranks of the
    decomposeParDict (method simple, slabs across the horizontal axis with more cells: ``split_of``); ``n_correctors``, ``n_outer``: PISO and
    PIMPLE loops; ``max_speed``: speed (m/s) taken as divergence; ``rel_tol``: relative
    tolerance of the pressure solver before the final corrector (absolute 1e-10); ``T0``
    (K): initial gas temperature, None for no gas energy; ``cp`` (J/(kg K)), ``kappa``
    (W/(m K)): the gas's heat capacity and conductivity; ``T_inlet`` (K, default T0): inlet
    temperature; ``T_walls``: {face: fixed temperature K} (other walls adiabatic)."""
    path = Path(path)
    missing = set(FACES) - set(boundaries)
    if missing:
        raise ValueError(f"boundaries: no kind given for {', '.join(sorted(missing))}")
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    corners = [[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]]
               for k, j, i in [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0),
                               (1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0)]]
    old_mesh = _text(path / "system" / "blockMeshDict")
    mesh = _dict(path / "system" / "blockMeshDict")
    mesh["convertToMeters"] = 1
    mesh["vertices"] = np.array(corners)
    mesh["blocks"] = ["hex", list(range(8)), list(map(int, cells)), "simpleGrading", [1, 1, 1]]
    mesh["boundary"] = [(face, {"type": "wall" if boundaries[face] in ("wall", "slip") else "patch",
                                "faces": [list(FACES[face])]}) for face in FACES]
    if _text(path / "system" / "blockMeshDict") != old_mesh:    # a mesh of other inputs: build anew
        shutil.rmtree(path / "constant" / "polyMesh", ignore_errors=True)

    control = _dict(path / "system" / "controlDict")
    control.update({
        "application": "collheatFoam", "startFrom": "startTime", "startTime": 0,
        "stopAt": "endTime", "endTime": 1e9, "deltaT": dt, "writeControl": "timeStep",
        "writeInterval": 10**9, "purgeWrite": 0, "writeFormat": "ascii", "writePrecision": 10,
        "timePrecision": 10, "runTimeModifiable": False, "maxSpeed": max_speed,
    })
    schemes = _dict(path / "system" / "fvSchemes")
    schemes.update({
        "ddtSchemes": {"default": "Euler"},
        "gradSchemes": {"default": ("Gauss", "linear")},
        "divSchemes": {"default": "none", "div(alphaPhi,U)": ("Gauss", "limitedLinearV", 1),
                       "div(((alpha*nuEff)*dev2(T(grad(U)))))": ("Gauss", "linear"),
                       "div(phi,U)": ("Gauss", "limitedLinearV", 1),
                       "div(alphaPhi,T)": ("Gauss", "limitedLinear", 1)},
        "laplacianSchemes": {"default": ("Gauss", "linear", "corrected")},
        "interpolationSchemes": {"default": "linear"},
        "snGradSchemes": {"default": "corrected"},
    })
    solution = _dict(path / "system" / "fvSolution")
    solution.update({
        "solvers": {
            "p": {"solver": "GAMG", "smoother": "DIC", "tolerance": 1e-10, "relTol": rel_tol},
            "pFinal": {"solver": "GAMG", "smoother": "DIC", "tolerance": 1e-10, "relTol": 0},
            '"(U|UFinal)"': {"solver": "smoothSolver", "smoother": "symGaussSeidel",
                           "tolerance": 1e-10, "relTol": 0},
            # tight: the gas energy is conserved to the residual of this solver
            '"(T|TFinal)"': {"solver": "PBiCGStab", "preconditioner": "DILU", "tolerance": 1e-14,
                             "relTol": 0, "maxIter": 1000},
        },
        "PIMPLE": {"momentumPredictor": True, "nOuterCorrectors": n_outer,
                   "nCorrectors": n_correctors, "nNonOrthogonalCorrectors": 0,
                   "pRefCell": 0, "pRefValue": 0},
    })
    decompose = _dict(path / "system" / "decomposeParDict")
    decompose.update({"numberOfSubdomains": nprocs, "method": "simple",
                      "coeffs": {"n": split_of(cells, nprocs)}})

    transport = _dict(path / "constant" / "transportProperties")
    transport.update({"transportModel": "Newtonian", "nu": nu, "rho": rho, "Cp": cp, "kappa": kappa})
    turbulence = _dict(path / "constant" / "turbulenceProperties")
    turbulence["simulationType"] = "laminar"
    g = _dict(path / "constant" / "g", "uniformDimensionedVectorField")
    g["dimensions"] = FoamFile.DimensionSet(length=1, time=-2)
    g["value"] = np.asarray(gravity, float)

    for field, cls, dims, zero in (("U", "volVectorField", dict(length=1, time=-1), np.zeros(3)),
                                   ("p", "volScalarField", dict(length=2, time=-2), 0.0)):
        f = _dict(path / "0" / field, cls)
        f["dimensions"] = FoamFile.DimensionSet(**dims)
        f["internalField"] = zero
        f["boundaryField"] = {face: _bc(kind, field) for face, kind in boundaries.items()}
    (path / "0" / "T").unlink(missing_ok=True)
    if T0 is not None:
        T_walls = T_walls or {}
        f = _dict(path / "0" / "T", "volScalarField")
        f["dimensions"] = FoamFile.DimensionSet(temperature=1)
        f["internalField"] = float(T0)
        f["boundaryField"] = {face: _bc((kind[0] if isinstance(kind, tuple) else kind,
                                         (T0, T0 if T_inlet is None else T_inlet, T_walls.get(face))), "T")
                              for face, kind in boundaries.items()}
    return path


def case_density(case: str | Path) -> tuple[float, str]:
    """The gas density [kg/m^3] of a user's OpenFOAM case and where it was found: ``rho`` of
    constant/transportProperties, else the uniform internalField of 0/rho (where CFDEM
    cases keep it). ValueError naming the file and the key when neither gives one number."""
    case = Path(case)
    props = FoamFile(case / "constant" / "transportProperties")
    if "rho" in props:
        return float(getattr(props["rho"], "value", props["rho"])), "constant/transportProperties: rho"
    field = case / "0" / "rho"
    if not field.is_file():
        raise ValueError(f"{case}: no gas density: constant/transportProperties has no rho and there is no "
                         f"0/rho (write e.g. 'rho [1 -3 0 0 0 0 0] 1.2;' into transportProperties)")
    value = FoamFile(field)["internalField"]
    if not np.isscalar(value) or float(value) <= 0:
        raise ValueError(f"{field}: internalField: the gas density must be one uniform positive value "
                         f"(collheatFoam solves an incompressible gas), got {str(value)[:60]}")
    return float(value), "0/rho: internalField"


def adopt_void_fraction(case: str | Path) -> bool:
    """In a copy of a user's case: CFDEM keeps the fluid fraction's boundary conditions in
    0/voidfraction (typically fixedValue 1 at inlets and outlets, so that an inlet's velocity
    is the superficial one even where the bed touches it); collheatFoam reads them from
    0/alpha. Writes 0/alpha from 0/voidfraction when the case has no 0/alpha; True if it did.
    Without either, the fraction is zeroGradient on every patch."""
    case = Path(case)
    source, target = case / "0" / "voidfraction", case / "0" / "alpha"
    if not source.is_file() or target.is_file():
        return False
    shutil.copy(source, target)
    f = FoamFile(target)
    f.object_ = "alpha"
    f["internalField"] = 1.0          # the host sends the fraction before the first step
    return True


CFDEM_DRAG = {"KochHillDrag": "koch_hill", "DiFeliceDrag": "difelice", "GidaspowDrag": "gidaspow"}
"""CFDEM's drag force models (couplingProperties' forceModels) the host has, as plugins.drag names."""
CFDEM_VOID_FRACTION = {"divided": "divided", "centre": "centre"}
"""CFDEM's voidFractionModel values the host has, as fluid.void_fraction values."""
CFDEM_ALPHA_MIN = 0.1
"""The floor of the fluid fraction of CFDEM's divided and centre models without alphaMin."""
CFDEM_NUSSELT = {"LiMason": "li_mason", "Gunn": "gunn", "Deen": "deen"}
"""CFDEM's Nusselt correlations (LaEuScalarTemp's NuCorrelation, scalarGeneralExchange's
switches) the host has, as plugins.convection names. CFDEM forms Re on the interstitial slip
d |U - v| / nu, the host (and the correlations' authors) on the superficial alpha d |U - v| / nu."""
CFDEM_DDT = {"off": False, "b": True}
"""CFDEM's useDDTvoidfraction values the host has, as fluid.ddt_alpha (its "a", the particles'
flux divergence in place of d(alpha)/dt, it has not)."""
MPI_EXCHANGE = ("twoWayMPI", "twoWayM2M")
"""CFDEM's in-memory data exchange models: CFDEM runs the DEM couplingInterval steps per
coupling, whatever the script's ``fix couple/cfd couple_every`` says (LIGGGHTS: "couple_every as
specified in LIGGGHTS is overriden by calling external program")."""
CFDEM_KNOWN = {"fluid.drag": CFDEM_DRAG, "fluid.void_fraction": CFDEM_VOID_FRACTION,
               "effects.convection": CFDEM_NUSSELT, "fluid.ddt_alpha": CFDEM_DDT}
"""The scene keys a CFDEM model name goes to, with the names the host has."""


def entry_line(path: Path, name: str) -> int:
    """The line of ``path`` where the entry ``name`` begins (for messages), 0 if not found."""
    for k, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        if line.split("//")[0].split()[:1] == [name]:
            return k
    return 0


def _values(d, keys=()):
    """(keys, value) of every entry of a parsed dictionary, its sub-dictionaries' too."""
    for key in d:
        value = d[key]
        if isinstance(value, dict) or hasattr(value, "as_dict"):
            yield from _values(value, keys + (str(key),))
        else:
            yield keys + (str(key),), value


def cfdem_dict(path: Path) -> dict:
    """A CFDEM dictionary (couplingProperties, liggghtsCommands) read strictly, as a plain dict:
    a file OpenFOAM cannot parse is named with foamlib's line and column, and an entry whose
    value runs on over several words is refused naming the file and its line: a ';' missing at
    the end of a line joins the next entry to it ('couplingInterval 100' then 'voidFractionModel
    divided;' read as one entry, so that voidFractionModel was missing and the host ran CFDEM's
    default, centre, with exit 0; CFDEM itself stops there). None of CFDEMcoupling-PUBLIC's
    tutorials has such an entry. ValueError (bad input) for either."""
    try:
        parsed = FoamFile(path).as_dict()
    except ValueError as exc:               # foamlib's FoamFileDecodeError
        raise ValueError(f"{path}: not a dictionary OpenFOAM reads: {exc}") from None
    for keys, value in _values(parsed):
        if isinstance(value, tuple) and any(isinstance(v, str) for v in value[1:]):
            words = " ".join(str(v) for v in value)
            raise ValueError(f"{path}:{entry_line(path, keys[-1])}: entry {' '.join(keys)} reads '{words}': a ';' "
                             f"is missing at the end of its line, and the next entry is read as part of its value "
                             "(CFDEM would stop there)")
    return parsed


def _entry(f, name: str):
    """A dictionary's entry ``name`` as OpenFOAM finds it: the key itself, else the last
    "(regex)" key that matches it whole (ErgunTestMPI: ``"(twoWayMPIProps|M2MProps)"``)."""
    if name in f:
        return f[name]
    for key in reversed(list(f.keys())):
        k = str(key)
        if k.startswith('"') and k.endswith('"') and re.fullmatch(k[1:-1], name):
            return f[key]
    return None


def coupling_properties(case: str | Path) -> dict[str, tuple[str, str, object]]:
    """What a CFDEM case's constant/couplingProperties says that a scene key also says, by
    scene key: ``{"fluid.drag": (entry, CFDEM's value, the host's value or None where it has
    none), ...}``; {} without the file. The keys:

    - the drag law (forceModels; several drag models are given as one joined by '+': the host
      has one law);
    - how a particle's volume goes to the cells (voidFractionModel) and the floor of the fluid
      fraction (its Props' alphaMin, CFDEM's default 0.1);
    - whether d(alpha)/dt is in the continuity equation (useDDTvoidfraction, CFDEM's default off);
    - the DEM steps per coupling (couplingInterval, with an in-memory exchange: ``MPI_EXCHANGE``);
    - the gas-particle heat transfer (forceModels' LaEuScalarTemp and its NuCorrelation, default
      LiMason; scalarGeneralExchange: useLiMason, useGeneralCorrelation, else Deen) and the
      gas's conductivity [W/(m K)] and heat capacity [J/(kg K)] that model names (lambda, Cp)."""
    path = Path(case) / "constant" / "couplingProperties"
    if not path.is_file():
        return {}
    f = cfdem_dict(path)
    found = {}
    models = [str(m) for m in (f.get("forceModels") or [])]
    drags = [m for m in models if m.endswith("Drag") and m != "noDrag"]
    if drags:
        name = "+".join(drags)
        found["fluid.drag"] = ("forceModels", name, CFDEM_DRAG.get(name))
    model = f.get("voidFractionModel")
    if model is not None:
        found["fluid.void_fraction"] = ("voidFractionModel", str(model), CFDEM_VOID_FRACTION.get(str(model)))
        floor = (_entry(f, f"{model}Props") or {}).get("alphaMin")
        if str(model) in CFDEM_VOID_FRACTION:   # (CFDEM's divided and centre clip at alphaMin, default 0.1)
            found["fluid.alpha_min"] = ((f"{model}Props alphaMin", f"{floor:g}", float(floor)) if floor is not None
                                        else (f"{model}Props", "no alphaMin: CFDEM's default 0.1", CFDEM_ALPHA_MIN))
    ddt = f.get("useDDTvoidfraction")
    ddt = "off" if ddt is False else str(ddt).strip('"') if ddt is not None else None
    found["fluid.ddt_alpha"] = (("useDDTvoidfraction", ddt, CFDEM_DDT.get(ddt)) if ddt is not None
                                else ("", "no useDDTvoidfraction: CFDEM's default off", False))
    interval = f.get("couplingInterval")
    if str(f.get("dataExchangeModel", "")) in MPI_EXCHANGE and isinstance(interval, int) and interval > 0:
        found["time.couple_every"] = ("couplingInterval", f"{interval}", interval)
    for heat in ("LaEuScalarTemp", "scalarGeneralExchange"):
        if heat not in models:
            continue
        props = _entry(f, f"{heat}Props") or {}
        if heat == "LaEuScalarTemp":
            nusselt = str(props.get("NuCorrelation", "LiMason")).strip('"')
        else:
            nusselt = ("LiMason" if props.get("useLiMason") is True else
                       "generalCorrelation" if props.get("useGeneralCorrelation") is True else "Deen")
        found["effects.convection"] = ("forceModels", f"{heat} ({nusselt})", CFDEM_NUSSELT.get(nusselt))
        for key, entry in (("fluid.conductivity", "lambda"), ("fluid.heat_capacity", "Cp")):
            if isinstance(props.get(entry), (int, float)) and not isinstance(props.get(entry), bool):
                found[key] = (f"{heat}Props {entry}", f"{props[entry]:g}", float(props[entry]))
        break
    return found


def start_time(case: str | Path) -> tuple[float, str | None]:
    """The time [s] a case's controlDict starts from (``startFrom startTime``: its startTime;
    ``latestTime``, ``firstTime``: the case's latest or first time folder, 0 without one) and
    the case's time folder of that time (None: the case has none, e.g. a CFDEM restart stage
    whose first stage the host ran, writing its times into its own output)."""
    case = Path(case)
    control = FoamFile(case / "system" / "controlDict")
    times = sorted((float(p.name), p.name) for p in case.iterdir() if p.is_dir() and is_time_name(p.name))
    how = str(control.get("startFrom", "startTime"))
    if how == "latestTime" or how == "firstTime":
        return times[-1 if how == "latestTime" else 0] if times else (0.0, None)
    t = float(getattr(control.get("startTime", 0.0), "value", control.get("startTime", 0.0)))
    return t, next((name for value, name in times if math.isclose(value, t, rel_tol=1e-9, abs_tol=1e-12)), None)


def is_time_name(name: str) -> bool:
    """Whether a folder's name is an OpenFOAM time (a finite number)."""
    try:
        return math.isfinite(float(name))
    except ValueError:
        return False


def coupling_script(case: str | Path) -> tuple[Path, str] | None:
    """The LIGGGHTS script a CFDEM case's coupling runs (its dataExchangeModel's Props
    ``liggghtsPath``, relative to the case folder, where CFDEM runs LIGGGHTS) and where that
    is said; None without one."""
    path = Path(case) / "constant" / "couplingProperties"
    if not path.is_file():
        return None
    f = cfdem_dict(path)
    exchange = str(f.get("dataExchangeModel", ""))
    script = (_entry(f, f"{exchange}Props") or {}).get("liggghtsPath")
    if not script:
        return None
    return Path(case) / str(script).strip('"'), f"{path} {exchange}Props liggghtsPath"


CFDEM_FORCES_KEPT = ("Archimedes", "gradPForce", "viscForce", "LaEuScalarTemp", "scalarGeneralExchange", "noDrag",
                     "fieldStore", "fieldTimeAverage", "particleCellVolume", "particleVolume", "volWeightedAverage",
                     "checkCouplingInterval")
"""CFDEM's force models (couplingProperties' forceModels, CFDEMcoupling-PUBLIC) besides the drag
laws that a case may list: the host's own interphase force stands for the pressure, viscous and
buoyancy ones (docs/fluid-cases.md), the heat transfer ones are read, and the rest only store
or average fields. Any other (MeiLift, virtualMassForce, a model of another CFDEM edition) is a
force the host does not have: such a case is refused."""


def cfdem_unsupported(case: str | Path) -> str | None:
    """Why the host cannot run a CFDEM case as it is written, or None: particles the mesh
    resolves (cfdemSolverIB: voidFractionModel IB or bigParticle, immersed-boundary force
    models), species transported besides T (the eulerian fields of scalarTransportProperties,
    scalarGeneralExchangeProps' partSpeciesNames), a flow that is not solved (solveFlow off), a
    force model the host does not have (``CFDEM_FORCES_KEPT``; drag laws are the scene's
    fluid.drag), or exchange fields smoothed (a smoothingModel other than off)."""
    coupling = Path(case) / "constant" / "couplingProperties"
    if not coupling.is_file():
        return None
    f = cfdem_dict(coupling)
    model = str(f.get("voidFractionModel", ""))
    forces = [str(m) for m in (f.get("forceModels") or []) if str(m).endswith("IB")]
    if model in ("IB", "bigParticle") or forces:
        where = f"voidFractionModel {model}" if model in ("IB", "bigParticle") else f"forceModels {' '.join(forces)}"
        return (f"the case resolves its particles on the mesh (an immersed boundary, as cfdemSolverIB: {coupling} "
                f"{where}); the host couples particles smaller than the cells, through a fluid fraction and a drag law")
    exchange = _entry(f, "scalarGeneralExchangeProps") or {}
    species = [(str(name), f"{coupling} scalarGeneralExchangeProps partSpeciesNames")
               for name in exchange.get("partSpeciesNames") or [] if str(name) != "none"]
    transport = Path(case) / "constant" / "scalarTransportProperties"
    if transport.is_file():
        t = FoamFile(transport)
        kind = str(t.get("scalarTransportModel", ""))
        species = [(str(name), f"{transport} {kind}Props eulerianFields")
                   for name in (_entry(t, f"{kind}Props") or {}).get("eulerianFields") or [] if str(name) != "T"] + species
    if species:
        names = ", ".join(sorted({name for name, _ in species}))
        return (f"the case transports species ({names}: {species[0][1]}); the host solves the gas flow and temperature "
                "only: remove the species from the case (and the script's couple/cfd/speciesConvection) to run its "
                "flow and heat")
    if f.get("solveFlow", True) is False:
        return (f"{coupling} solveFlow off: the case keeps its gas still (CFDEM computes only the fluid fraction and "
                "the forces); the host always solves the gas flow: remove the entry to have the flow solved")
    other = [str(m) for m in (f.get("forceModels") or []) if not str(m).endswith("Drag")
             and str(m) not in CFDEM_FORCES_KEPT]
    if other:
        return (f"{coupling} forceModels {' '.join(other)}: a force the host does not have (its interphase force is "
                f"drag, buoyancy and the pressure gradient: docs/fluid-cases.md); remove {other[0]} to run without it")
    smoothing = f.get("smoothingModel")
    if smoothing not in (None, False) and str(smoothing) not in ("off", "noSmoothing"):
        return (f"{coupling} smoothingModel {smoothing}: CFDEM smooths the exchange fields, the host does not; "
                "set 'smoothingModel off;' to run without it")
    return None


def adopt_piso(case: str | Path) -> bool:
    """In a copy of a user's case: CFDEM's solvers (cfdemSolverPiso, cfdemSolverPisoScalar, ...)
    and pisoFoam read their loop from fvSolution's PISO dictionary, collheatFoam from PIMPLE.
    Where the case's application is such a PISO solver, or the case has PISO and no PIMPLE,
    PIMPLE becomes PISO's entries (nCorrectors, nNonOrthogonalCorrectors, pRefCell,
    pRefValue, ...) with one outer corrector: PIMPLE run as PISO, with the user's settings.
    Returns True if it did."""
    f = FoamFile(Path(case) / "system" / "fvSolution")
    if "PISO" not in f:
        return False
    application = str(FoamFile(Path(case) / "system" / "controlDict").get("application", ""))
    if "PIMPLE" in f and "piso" not in application.lower():
        return False
    loop = dict(f["PISO"])
    loop["nOuterCorrectors"] = 1
    f["PIMPLE"] = loop
    return True


MEAN_VELOCITY_FORCES = {"meanVelocityForce": False, "meanSupVelocityForce": True}
"""fvOptions types that drive a mean velocity, and whether the mean is superficial (CFDEM's)."""


def adopt_mean_velocity_force(case: str | Path) -> list[str]:
    """In a copy of a user's case: an fvOptions entry of OpenFOAM's meanVelocityForce or
    CFDEM's meanSupVelocityForce becomes collheatFoam's collheatMeanVelocityForce (the same
    control for its face-momentum form, with ``superficial`` true for CFDEM's), its
    ``<type>Coeffs`` entries moved up. v1912's own meanVelocityForce misjudges the flow's
    response in collheatFoam and overshoots (plugins/openfoam/collheatFoam/
    collheatMeanVelocityForce.H). Returns the entries changed, as 'NAME (TYPE)'."""
    changed = []
    for rel in ("system/fvOptions", "constant/fvOptions"):
        path = Path(case) / rel
        if not path.is_file():
            continue
        f = FoamFile(path)
        for name in list(f.keys()):
            entry = f[name] if name is not None else None
            if not hasattr(entry, "get") or str(entry.get("type")) not in MEAN_VELOCITY_FORCES:
                continue
            kind = str(entry["type"])
            new = {k: v for k, v in dict(entry).items() if k != kind + "Coeffs"}
            new.update({k: v for k, v in dict(entry.get(kind + "Coeffs", {})).items()
                        if k not in ("twoPhase", "coupled", "voidfractionField", "alphaField", "alphaMin")})
            new["type"] = "collheatMeanVelocityForce"
            new["superficial"] = MEAN_VELOCITY_FORCES[kind]
            f[name] = new
            changed.append(f"{name} ({kind})")
    return changed


def add_final_solvers(case: str | Path) -> list[str]:
    """In a copy of a user's case: OpenFOAM v1912 looks up 'XFinal' solver settings for the
    last corrector of every field X it solves; cases written for older versions (CFDEM's
    tutorials) give only 'X'. Adds 'XFinal' = X with relTol 0 where it is missing; returns
    the names added."""
    f = FoamFile(Path(case) / "system" / "fvSolution")
    if "solvers" not in f:
        return []
    solvers = f["solvers"]
    keys = list(solvers.keys())
    added = []
    for key in keys:
        final = key[:-1] + 'Final"' if key.endswith('"') else key + "Final"
        if key.endswith(('Final', 'Final"')) or final in keys:
            continue
        entry = dict(solvers[key])
        entry["relTol"] = 0.0
        f["solvers"][final] = entry
        added.append(final)
    return added


def drop_phase(text: str, phase: str) -> str:
    """``text`` with a phase's suffix dropped from the names it follows (``U.air`` -> ``U``,
    ``alphaPhi.air`` -> ``alphaPhi``, ``U.airFinal`` -> ``UFinal``): collheatFoam's names for a
    case of OpenFOAM's particle solvers (MPPICFoam, DPMFoam), which name the gas's fields
    after its phase."""
    return re.sub(rf"(?<=[A-Za-z0-9_)])\.{re.escape(phase)}(?=Final\b|\b)", "", text) if phase else text


def case_phase(case: str | Path) -> str:
    """The gas phase's name a case of OpenFOAM's particle solvers gives (transportProperties'
    ``continuousPhase``), '' for a single-phase case."""
    props = Path(case) / "constant" / "transportProperties"
    if not props.is_file():
        return ""
    found = re.search(r"^\s*continuousPhase\s+(\w+)\s*;", props.read_text(errors="replace"), re.M)
    return found.group(1) if found else ""


SOLVER_SCHEMES = {"div(alphaPhi,U)": ("Gauss", "linearUpwindV", "grad(U)"),
                  "div(((alpha*nuEff)*dev2(T(grad(U)))))": ("Gauss", "linear")}
"""The divergence schemes collheatFoam's momentum equation asks for (UEqn.H: the convection of
U by alphaPhi, the deviatoric stress of the laminar or turbulent gas), with what the host writes
into a copied case whose fvSchemes has neither nor a default: MPPICFoam's and DPMFoam's own
choices (their tutorials' fvSchemes)."""


def adopt_other_solver(case: str | Path) -> list[str]:
    """A copied case written for another OpenFOAM solver, made collheatFoam's in place; returns
    what was changed, one line each (printed as notes):

    - a phase's suffix (MPPICFoam, DPMFoam: ``continuousPhase air``) dropped from every file
      name and text of 0/, constant/ and system/ but the particle cloud's (``U.air`` -> ``U``,
      ``turbulenceProperties.air`` -> ``turbulenceProperties``, ``phi.air`` in an
      ``inletOutlet`` -> ``phi``, ``rho.air`` -> ``rho``);
    - the particle cloud's files (kinematicCloud*, *CloudProperties) removed: the particles
      are the DEM's;
    - 0.orig copied to 0 where the case keeps its fields there (OpenFOAM's tutorials restore it
      in their Allrun); gzipped dictionaries (``blockMeshDict.gz``) unpacked, which OpenFOAM
      reads either way and the host's checks read plain;
    - constant/turbulenceProperties written laminar where the case has none;
    - fvSchemes' divergence schemes collheatFoam asks for (``SOLVER_SCHEMES``) added where the
      case has neither them nor a default."""
    case = Path(case)
    notes = []
    if not (case / "0").is_dir() and (case / "0.orig").is_dir():
        shutil.copytree(case / "0.orig", case / "0")
        notes.append("0/ copied from 0.orig (as the tutorial's Allrun does)")
    for sub in ("0", "constant", "system"):
        for path in sorted((case / sub).glob("*") if (case / sub).is_dir() else []):
            if path.name.startswith("kinematicCloud") or "CloudProperties" in path.name:
                path.unlink()           # the particle cloud's: the particles are the DEM's
            elif path.suffix == ".gz":
                path.with_suffix("").write_bytes(gzip.decompress(path.read_bytes()))
                path.unlink()
                notes.append(f"{path.relative_to(case)} unpacked")
    phase = case_phase(case)
    if phase:
        renamed = []
        for sub in ("0", "constant", "system"):
            for path in sorted((case / sub).rglob("*") if (case / sub).is_dir() else []):
                if not path.is_file() or "polyMesh" in path.parts:
                    continue
                text = path.read_text(errors="replace")
                target = path.with_name(drop_phase(path.name, phase))
                target.write_text(drop_phase(text, phase))
                if target != path:
                    path.unlink()
                    renamed.append(f"{path.relative_to(case)} -> {target.relative_to(case)}")
        notes.append(f"the gas phase '{phase}' (continuousPhase) read as collheatFoam's single gas: "
                     f"its suffix dropped from names ({'; '.join(renamed) or 'no file renamed'})")
    turbulence = case / "constant" / "turbulenceProperties"
    if not turbulence.is_file() and (case / "constant").is_dir():
        turbulence.write_text("FoamFile\n{\n    version 2.0;\n    format ascii;\n    class dictionary;\n"
                              "    object turbulenceProperties;\n}\nsimulationType laminar;\n")
        notes.append("constant/turbulenceProperties written with simulationType laminar (the case has none)")
    schemes = case / "system" / "fvSchemes"
    if schemes.is_file():
        f = FoamFile(schemes)
        div = f.get("divSchemes") or {}
        if str(div.get("default", "none")).strip() == "none":
            added = {k: v for k, v in SOLVER_SCHEMES.items() if k not in div}
            if added:
                f["divSchemes"] = {**dict(div), **added}
                notes.append("fvSchemes divSchemes: " + "; ".join(f"{k} {' '.join(v)}" for k, v in added.items())
                             + " added (collheatFoam's momentum equation asks for them)")
    return notes


def mesh_extent(case: str | Path) -> tuple[np.ndarray, np.ndarray] | None:
    """(lo, hi) [m] of a case's mesh points (constant/polyMesh/points), None without them."""
    path = Path(case) / "constant" / "polyMesh" / "points"
    if not path.is_file():
        return None
    points = np.asarray(FoamFile(path)[None], float).reshape(-1, 3)
    return points.min(axis=0), points.max(axis=0)


def _face_areas(case: Path, start: int, count: int) -> np.ndarray:
    """Area vectors [m^2] of the mesh's faces start .. start + count (outward on the boundary)."""
    mesh = case / "constant" / "polyMesh"
    points = np.asarray(FoamFile(mesh / "points")[None], float).reshape(-1, 3)
    faces = FoamFile(mesh / "faces")[None][start:start + count]
    areas = np.zeros((len(faces), 3))
    for k, face in enumerate(faces):
        p = points[np.asarray(face, int)]
        areas[k] = 0.5 * np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(axis=0)
    return areas


def _table_at(rows, t: float) -> np.ndarray:
    """OpenFOAM's table: linear between its rows, held beyond its first and last."""
    times = np.array([r[0] for r in rows], float)
    values = np.array([r[1] for r in rows], float).reshape(len(rows), -1)
    return np.array([np.interp(t, times, values[:, i]) for i in range(values.shape[1])])


def inlet_speed(case: str | Path, start: str = "0"):
    """The mean speed [m/s] at which the gas of a user's case comes in through its patches of
    fixed inflow, as a function of the time [s]: the inflow [m^3/s] over those patches' area
    [m^2]. Read from the mesh (constant/polyMesh) and the start time's U: ``fixedValue`` with a
    uniform value, ``uniformFixedValue`` (constant or table) and ``flowRateInletVelocity`` with a
    constant ``volumetricFlowRate``. None where no patch of those lets gas in (a closed or a
    periodic case) or the mesh is not written yet."""
    case = Path(case)
    try:
        boundary = FoamFile(case / "constant" / "polyMesh" / "boundary")[None]
        U = FoamFile(case / start / "U")["boundaryField"]
    except (OSError, KeyError, ValueError):
        return None
    inlets = []                         # (area vectors, velocity of t, or None; flow rate or None)
    for name, patch in boundary:
        entry = U.get(name) if hasattr(U, "get") else None
        kind = entry.get("type") if entry is not None else None
        if kind == "fixedValue" and np.ndim(entry.get("value")) == 1:
            value = np.asarray(entry["value"], float)
            speed = lambda t, v=value: v
        elif kind == "uniformFixedValue" and isinstance(entry.get("uniformValue"), tuple):
            how, data = entry["uniformValue"][0], entry["uniformValue"][1]
            if how == "constant":
                speed = lambda t, v=np.asarray(data, float): v
            elif how == "table":
                speed = lambda t, rows=data: _table_at(rows, t)
            else:
                continue
        elif kind == "flowRateInletVelocity" and isinstance(entry.get("volumetricFlowRate"), (int, float)):
            inlets.append((_face_areas(case, patch["startFace"], patch["nFaces"]), None,
                           float(entry["volumetricFlowRate"])))
            continue
        else:
            continue
        inlets.append((_face_areas(case, patch["startFace"], patch["nFaces"]), speed, None))

    def at(t: float) -> float:
        flow = area = 0.0
        for S, speed, rate in inlets:
            q = rate if rate is not None else float(-np.sum(S @ speed(t)))
            if q > 0:
                flow, area = flow + q, area + float(np.linalg.norm(S, axis=1).sum())
        return flow / area if area > 0 else float("nan")

    return at if inlets else None
