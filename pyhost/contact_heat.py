"""Per-collision heat and restitution from the plugin, for the collisions a sample found.

The plugin gets the *real* material properties of the scene (never the DEM's softened
modulus). A pair of materials is one ``plugins.heat.Pair`` with the effective modulus of
the two (eq. 4) and the yield stress, b1 and b2 of the softer one (lower yield stress):
plastic deformation starts in the body that yields first.
"""
from __future__ import annotations


import numpy as np

from plugins.heat import Pair, collide, effective_modulus
from plugins.heat.fast import collide_fast


def pair_properties(mat1, mat2) -> dict:
    """Pair fields (SI) for materials mat1 (body 1) and mat2 (body 2 or wall) of a scene."""
    soft = mat1 if mat1.yield_stress <= mat2.yield_stress else mat2
    return dict(rho1=mat1.density, rho2=mat2.density, c1=mat1.heat_capacity, c2=mat2.heat_capacity,
                k1=mat1.conductivity, k2=mat2.conductivity, Y=soft.yield_stress, b1=soft.b1, b2=soft.b2,
                Estar=float(effective_modulus(mat1.youngs_modulus, mat1.poisson_ratio,
                                              mat2.youngs_modulus, mat2.poisson_ratio)))


def evaluate(model: str, path: str, materials: list, mat_i, mat_j, R_i, R_j, v0, dT):
    """Q [J] (> 0 from i to j), e [-] and t_coll [s] of collisions between bodies of material
    indices mat_i, mat_j (into ``materials``), radii R_i, R_j [m] (inf for walls), normal
    impact speeds v0 [m/s] and temperature differences dT = T_i - T_j [K]."""
    n = len(v0)
    Q, e, t_coll = np.empty(n), np.empty(n), np.empty(n)
    for a, b in set(zip(np.asarray(mat_i).tolist(), np.asarray(mat_j).tolist())):
        sel = np.flatnonzero((mat_i == a) & (mat_j == b))
        props = pair_properties(materials[a], materials[b])
        if path == "fast":
            pair = Pair(R1=R_i[sel], R2=R_j[sel], dT=dT[sel], **props)
            out = collide_fast(v0[sel], pair, model, outputs=("Q", "e", "t_coll"))
            Q[sel], e[sel], t_coll[sel] = out["Q"], out["e"], out["t_coll"]
        else:
            for k in sel:
                c = collide(float(v0[k]), Pair(R1=float(R_i[k]), R2=float(R_j[k]), dT=float(dT[k]), **props), model)
                Q[k], e[k], t_coll[k] = c.Q, c.e, c.t_coll
    return Q, e, t_coll


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
