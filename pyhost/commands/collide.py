"""``python -m pyhost collide``: one or more collisions of a pair, printed as JSON or a table."""
from __future__ import annotations

import argparse
import json
import math
import sys
import warnings

import numpy as np

from plugins.heat import MODELS, PAPER_SET, Pair, collide
from plugins.heat.comparison import COMPARISON, DemPair
from plugins.heat.exact import OUTPUT_KEYS
from plugins.heat.fast import REGIMES, collide_fast
from plugins.heat.validity import check_scales
from plugins.heat.validity import flags as validity_flags
from pyhost.cli import UserError
from pyhost.engines.liggghts.names import CONDUCTION

HELP = "heat conducted and rebound of head-on collisions (models A, B, C; SI units)"

PAIR_OPTIONS = (
    ("R1", "radius of body 1 [m]"), ("R2", "radius of body 2 [m] (see --wall)"),
    ("rho1", "density of body 1 [kg/m^3]"), ("rho2", "density of body 2 [kg/m^3]"),
    ("Estar", "effective Young's modulus E* [Pa]"), ("Y", "yield stress [Pa]"),
    ("b1", "mean pressure at first yield / Y [-]"), ("b2", "mean pressure, fully plastic / Y [-]"),
    ("c1", "heat capacity of body 1 [J/(kg K)]"), ("c2", "heat capacity of body 2 [J/(kg K)]"),
    ("k1", "conductivity of body 1 [W/(m K)]"), ("k2", "conductivity of body 2 [W/(m K)]"),
    ("dT", "temperature difference T1 - T2 [K]"),
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--model", default="A", choices=sorted(MODELS) + sorted(COMPARISON) + ["all"],
                   help="contact model: the paper's A, B, C ('all' gives each), or a comparison model of "
                        "plugins/heat/comparison (its own closed form or integration, whatever --method; "
                        "e is null: it gives no restitution)")
    p.add_argument("--v0", type=float, nargs="+", default=[1.0],
                   help="normal impact speed(s) [m/s]; several give a JSON list")
    p.add_argument("--method", default="exact", choices=("exact", "fast", "fit"),
                   help="exact: reference quadrature; fast: tables (relative error < 1e-6); "
                        "fit: fitted relations, e, t_coll and Q only (plugins/heat/fit.py: "
                        "e to 5e-4, t_coll to 6 %%, Q to 2.5 %%)")
    p.add_argument("--wall", action="store_true",
                   help="body 2 is a flat wall (R2 = inf, m* = m1); rho2, c2, k2 describe the wall")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    for name, text in PAIR_OPTIONS:
        p.add_argument(f"--{name}", type=float, default=PAPER_SET[name], help=text)
    p.add_argument("--c-log", dest="c_log", type=float, default=None,
                   help="constant of ln in eq. (8) [-]; default 3*b1 (continuous force)")
    p.add_argument("--dem-Estar", dest="dem_Estar", type=float, default=None,
                   help="the DEM's softened effective modulus [Pa] (the comparison models that need the DEM's contact)")
    p.add_argument("--dem-e", dest="dem_e", type=float, default=None,
                   help="the DEM's coefficient of restitution [-] (with --dem-Estar)")
    p.add_argument("--dem-Estar-original", dest="dem_Estar_original", type=float, default=None,
                   help=f"{CONDUCTION}'s original modulus [Pa] (softened_corrected); default --Estar")


def pair_from_args(args) -> Pair:
    values = {name: getattr(args, name) for name, _ in PAIR_OPTIONS}
    if args.wall:
        values["R2"] = math.inf
    return Pair(c_log=args.c_log, **values)


def dem_from_args(args, model: str) -> DemPair | None:
    """The DEM's contact a comparison model needs (None if it needs none)."""
    if not COMPARISON[model].needs_dem:
        return None
    if args.dem_Estar is None or args.dem_e is None:
        from pyhost.cli import UserError
        raise UserError(f"--model {model} needs the DEM's softened contact: give --dem-Estar [Pa] and --dem-e [-]")
    return DemPair(Ystar=args.dem_Estar, restitution=args.dem_e,
                   Ystar_original=args.Estar if args.dem_Estar_original is None else args.dem_Estar_original)


def evaluate(args) -> list[dict]:
    pair = pair_from_args(args)
    models = sorted(MODELS) if args.model == "all" else [args.model]
    rows = []
    for model in models:
        if model in COMPARISON:
            out = COMPARISON[model].heat(np.array(args.v0), pair, dem_from_args(args, model))
            rows += [{"model": model, "v0": v, "Q": float(out["Q"][j]), "t_coll": float(out["t_coll"][j]),
                      "delta_max": float(out["delta_max"][j]), "e": None} for j, v in enumerate(args.v0)]
        elif args.method == "fit":
            from plugins.heat.fit import collide_fit
            out = collide_fit(np.array(args.v0), pair, model)
            rows += [{"model": model, "v0": v, **{k: float(out[k][j]) for k in ("e", "t_coll", "Q")}}
                     for j, v in enumerate(args.v0)]
        elif args.method == "exact":
            rows += [{"model": model, "v0": v, **collide(v, pair, model).to_dict()} for v in args.v0]
        else:
            out = collide_fast(np.array(args.v0), pair, model)
            for j, v in enumerate(args.v0):
                row = {k: float(out[k][j]) for k in OUTPUT_KEYS if k not in ("regime", "flags")}
                row["regime"] = REGIMES[int(out["regime"][j])]
                bits = int(out["flags"][j])
                row["flags"] = [f for b, f in ((1, "negative_residual_indentation"),
                                               (2, "restitution_above_one")) if bits & b]
                rows.append({"model": model, "v0": v, **{k: row[k] for k in OUTPUT_KEYS}})
    return rows


def checked(args) -> list[dict]:
    """The rows of ``evaluate``, each with the flags of plugins.heat.validity; UserError for
    a pair or a speed outside double precision (an output would be NaN or Infinity)."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        pair = pair_from_args(args)
        check_scales(pair)
        try:
            rows = evaluate(args)
        except ArithmeticError as exc:
            raise UserError(f"--v0 {args.v0}: the collision is outside double precision ({exc})") from None
    for row in rows:
        found = validity_flags(pair, row["v0"], row, args.method)
        if "overflow" in found:
            bad = [k for k, v in row.items() if isinstance(v, float) and not math.isfinite(v)]
            raise UserError(f"--v0 {row['v0']:g}, --dT {args.dT:g}: {', '.join(bad)} overflow (not finite in "
                            f"double precision); outside the range of the models")
        row["flags"] = row.get("flags", []) + found
        if found:
            print(f"warning: model {row['model']}, v0 = {row['v0']:g} m/s: {', '.join(found)} "
                  f"(plugins/heat/validity.py)", file=sys.stderr)
    return rows


def run(args) -> int:
    rows = checked(args)
    if args.json:
        print(json.dumps(rows[0] if len(rows) == 1 else rows, indent=1))
        return 0
    cols = ("model", "v0", "regime", "delta_max", "t_coll", "e", "Q", "Q_closed_form")
    print("  ".join(f"{c:>15}" for c in cols) + "  flags")
    for r in rows:
        cells = [f"{r[c]:>15.6g}" if isinstance(r.get(c), float) else f"{r.get(c) or '-':>15}" for c in cols]
        print("  ".join(cells) + "  " + ",".join(r.get("flags", [])))
    return 0
