"""Heat of many collisions at once between bodies of named materials: the host's and post's
way into the plugin (``collide`` and ``collide_fast`` take one pair of materials at a time).

A material is any object with the fields of ``pyhost.scene.Material`` (SI): density,
heat_capacity, conductivity, youngs_modulus, poisson_ratio (the real material), yield_stress,
b1, b2, and ``dem`` (youngs_modulus, poisson_ratio, restitution of the DEM's softened contact).

The plugin gets the *real* material properties (never the DEM's softened modulus). A pair of
materials is one ``Pair`` with the effective modulus of the two (eq. 4) and the yield stress,
b1 and b2 of the softer one (lower yield stress): plastic deformation starts in the body that
yields first. Comparison models (``plugins.heat.comparison``) are evaluated by the same call;
those that need the DEM's softened contact get it from the materials' ``dem`` tables
(``dem_pair``).
"""
from __future__ import annotations

import numpy as np

from plugins.heat import MODEL_NAMES, MODELS, Pair, collide, effective_modulus
from plugins.heat.comparison import COMPARISON, DemPair
from plugins.heat.exchange import exchange_heat, temperature_difference
from plugins.heat.fast import collide_fast


def pair_properties(mat1, mat2) -> dict:
    """Pair fields (SI) for materials mat1 (body 1) and mat2 (body 2 or wall) of a scene."""
    soft = mat1 if mat1.yield_stress <= mat2.yield_stress else mat2
    return dict(rho1=mat1.density, rho2=mat2.density, c1=mat1.heat_capacity, c2=mat2.heat_capacity,
                k1=mat1.conductivity, k2=mat2.conductivity, Y=soft.yield_stress, b1=soft.b1, b2=soft.b2,
                Estar=float(effective_modulus(mat1.youngs_modulus, mat1.poisson_ratio,
                                              mat2.youngs_modulus, mat2.poisson_ratio)))


def dem_pair(mat1, mat2) -> DemPair:
    """The DEM's contact between materials mat1 and mat2 as LIGGGHTS forms it: Yeff from the
    ``dem`` Young's moduli and Poisson ratios, the mean restitution (the host writes that
    into coefficientRestitution), and heat/gran's original modulus from the real Young's
    moduli with the DEM's Poisson ratios."""
    d1, d2 = mat1.dem, mat2.dem
    return DemPair(
        Ystar=float(effective_modulus(d1.youngs_modulus, d1.poisson_ratio, d2.youngs_modulus, d2.poisson_ratio)),
        restitution=0.5 * (d1.restitution + d2.restitution),
        Ystar_original=float(effective_modulus(mat1.youngs_modulus, d1.poisson_ratio,
                                               mat2.youngs_modulus, d2.poisson_ratio)))


def evaluate(model: str, path: str, materials: list, mat_i, mat_j, R_i, R_j, v0, dT):
    """Q [J] (> 0 from i to j), e [-] and t_coll [s] of collisions between bodies of material
    indices mat_i, mat_j (into ``materials``), radii R_i, R_j [m] (inf for walls), normal
    impact speeds v0 [m/s] and temperature differences dT = T_i - T_j [K].
    ``model`` is A, B, C or a comparison model (one path only; e is NaN for those)."""
    return evaluate_flagged(model, path, materials, mat_i, mat_j, R_i, R_j, v0, dT)[:3]


def evaluate_flagged(model: str, path: str, materials: list, mat_i, mat_j, R_i, R_j, v0, dT):
    """``evaluate`` and, per collision, whether it leaves the models' range as
    plugins.heat.validity flags it for ``collide``: an output not finite (overflow) or the
    indentation delta_max beyond the smaller radius (delta_max_exceeds_radius), where the
    half-space contact theory has no meaning (a 2000 m/s impact)."""
    if model not in MODELS and model not in COMPARISON:
        raise ValueError(f"unknown contact heat model {model!r}; choices: {', '.join(MODEL_NAMES)}")
    n = len(v0)
    Q, e, t_coll, delta = np.empty(n), np.empty(n), np.empty(n), np.zeros(n)
    for a, b in set(zip(np.asarray(mat_i).tolist(), np.asarray(mat_j).tolist())):
        sel = np.flatnonzero((mat_i == a) & (mat_j == b))
        props = pair_properties(materials[a], materials[b])
        if model in COMPARISON:
            pair = Pair(R1=R_i[sel], R2=R_j[sel], dT=dT[sel], **props)
            out = COMPARISON[model].heat(v0[sel], pair, dem_pair(materials[a], materials[b]))
            Q[sel], e[sel], t_coll[sel] = out["Q"], out["e"], out["t_coll"]
            delta[sel] = out["delta_max"]
        elif path == "fast":
            pair = Pair(R1=R_i[sel], R2=R_j[sel], dT=dT[sel], **props)
            out = collide_fast(v0[sel], pair, model, outputs=("Q", "e", "t_coll", "delta_max"))
            Q[sel], e[sel], t_coll[sel], delta[sel] = out["Q"], out["e"], out["t_coll"], out["delta_max"]
        else:
            for k in sel:
                c = collide(float(v0[k]), Pair(R1=float(R_i[k]), R2=float(R_j[k]), dT=float(dT[k]), **props), model)
                Q[k], e[k], t_coll[k], delta[k] = c.Q, c.e, c.t_coll, c.delta_max
    with np.errstate(invalid="ignore"):
        flagged = ~(np.isfinite(Q) & np.isfinite(t_coll) & (np.isfinite(e) | np.isnan(e))) \
            | (delta > np.minimum(R_i, R_j))
    return Q, e, t_coll, flagged


def side_heat(models, path: str, materials: list, mat_i, mat_j, R_i, R_j, v0, dT) -> dict:
    """{model: Q [J]} of each side model on the same collisions (``evaluate`` with each);
    side models only report, they move no heat and give no restitution."""
    return {m: evaluate(m, path, materials, mat_i, mat_j, R_i, R_j, v0, dT)[0] for m in models}


def move_heat(models, path: str, materials: list, mat_i, mat_j, R_i, R_j, v0, T, C, i, j, T_wall=None, shift=None):
    """Collisions in their order, their heat moved (``exchange_heat``: T [K] changed in place,
    C = m c [J/K] per particle; i, j particle indices, j >= WALL_BASE a wall) by the first of
    ``models``, the others as side columns at the same temperature differences (nothing moved).
    Other arguments as ``evaluate``. Returns the collisions' columns (Q [J] moved from i to j,
    e [-], t_coll [s] and Q_<model> of each side model), whether each is outside the models'
    range (``evaluate_flagged``), and how many were capped."""
    args = (path, materials, mat_i, mat_j, R_i, R_j, v0, np.ones(len(v0)))
    G, e, t_coll, flagged = evaluate_flagged(models[0], *args)              # Q per kelvin [J/K]
    side = {}
    if len(models) > 1:
        dT = temperature_difference(T, i, j, T_wall) + (0.0 if shift is None else shift)
        side = {f"Q_{m}": g * dT for m, g in side_heat(models[1:], *args).items()}
    moved, capped, _ = exchange_heat(T, C, i, j, G, T_wall, shift)
    return dict(Q=moved, e=e, t_coll=t_coll, **side), flagged, capped
