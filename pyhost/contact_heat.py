"""Per-collision heat and restitution from the plugin, for the collisions a sample found.

The plugin gets the *real* material properties of the scene (never the DEM's softened
modulus). A pair of materials is one ``plugins.heat.Pair`` with the effective modulus of
the two (eq. 4) and the yield stress, b1 and b2 of the softer one (lower yield stress):
plastic deformation starts in the body that yields first.

Comparison models (``plugins.heat.comparison``) are evaluated by the same call. Those that
need the DEM's softened contact get it from the materials' ``dem`` tables (``dem_pair``).
"""
from __future__ import annotations

import numpy as np

from plugins.heat import MODEL_NAMES, MODELS, Pair, collide, effective_modulus
from plugins.heat.comparison import COMPARISON, DemPair
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
            delta[sel] = out.get("delta_max", 0.0)
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


def restitution_impulse(v_i, v_j, m_i, m_j, normal, e_target, v0):
    """Velocity changes [m/s] that make the normal separation speed e_target * v0, conserving
    momentum. normal points from j to i; v_j, m_j of a wall are 0 and inf. e above 1 is
    clipped to 1 (returned count), so no collision gains energy."""
    e_target = np.asarray(e_target, float)
    clipped = int(np.sum(e_target > 1.0))
    e_target = np.minimum(e_target, 1.0)
    separation = np.einsum("ij,ij->i", v_i - v_j, normal)
    change = e_target * v0 - separation
    wall = np.isinf(m_j)
    share_i = np.where(wall, 1.0, m_j / np.where(wall, 1.0, m_i + m_j))
    share_j = np.where(wall, 0.0, m_i / np.where(wall, 1.0, m_i + m_j))
    return (share_i * change)[:, None] * normal, -(share_j * change)[:, None] * normal, clipped


def heat_by_model_offline(scene, collisions, models) -> dict:
    """{model: heat between particles [J], sum of |Q|} of each model on the collisions of a
    finished run (``collisions``: the columns of its collisions.csv as arrays: i, j, wall
    (1-based, 0 for none), v0, Q, model). Each collision's dT is the one the run used,
    Q / (Q per kelvin of the run's own model), so a model's column is what a side column
    would have held (collisions with an adiabatic wall or capped ones carry no dT back).
    Box scenes only: particle ids are the order of ``place_particles``."""
    from pyhost.dem_input import material_index, place_particles

    p = place_particles(scene)
    materials = list(scene.materials.values())
    wall_mat = np.array([material_index(scene)[w.material] for w in scene.walls] or [0], int)
    i = np.asarray(collisions["i"], int) - 1
    w = np.asarray(collisions["wall"], int)
    wall = w > 0
    j = np.where(wall, 0, np.asarray(collisions["j"], int) - 1)
    mi, R_i = p.material[i], p.radius[i]
    mj = np.where(wall, wall_mat[np.maximum(w - 1, 0)], p.material[j])
    R_j = np.where(wall, np.inf, p.radius[j])
    v0, ones = np.asarray(collisions["v0"], float), np.ones(len(i))
    main = set(np.asarray(collisions["model"]).tolist())
    if len(main) != 1:
        raise ValueError(f"collisions.csv holds {len(main)} heat models ({sorted(main)}); expected one")
    G_main = evaluate(main.pop(), "fast", materials, mi, mj, R_i, R_j, v0, ones)[0]
    dT = np.asarray(collisions["Q"], float) / G_main
    return {m: float(np.abs(evaluate(m, "fast", materials, mi, mj, R_i, R_j, v0, ones)[0] * dT)[~wall].sum())
            for m in models}
