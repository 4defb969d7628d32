"""Plugin calls for arrays of collisions and the restitution impulse (no engines)."""
import math

import numpy as np
import pytest
from conftest import steel_material

from plugins.heat import Pair, collide
from plugins.dem.impulse import restitution_impulse
from plugins.heat.batch import evaluate, evaluate_flagged, pair_properties
from pyhost.schema import DemContact, Material

DEM = DemContact(youngs_modulus=1e7, restitution=0.9)
STEEL = steel_material(DEM)
GLASS = Material(2500.0, 63e9, 0.22, 1e9, 840.0, 1.0, DEM, b1=1.1, b2=3.0)


def test_pair_takes_softer_yield_and_effective_modulus():
    p = pair_properties(GLASS, STEEL)
    assert p["Y"] == 300e6 and p["b2"] == 2.8 and p["rho1"] == 2500.0 and p["k2"] == 45.0
    assert p["Estar"] == pytest.approx(1 / ((1 - 0.22**2) / 63e9 + (1 - 0.09) / 210e9))


@pytest.mark.parametrize("path", ["exact", "fast"])
def test_evaluate_groups_by_material_pair(path):
    mats = [STEEL, GLASS]
    mi, mj = np.array([0, 1, 0]), np.array([1, 1, 0])
    R_i, R_j = np.array([1e-3, 2e-3, 1e-3]), np.array([2e-3, 2e-3, math.inf])
    v0, dT = np.array([0.3, 1.0, 2.0]), np.array([50.0, -10.0, 5.0])
    Q, e, t = evaluate("C", path, mats, mi, mj, R_i, R_j, v0, dT)
    for k in range(3):
        ref = collide(v0[k], Pair(R1=R_i[k], R2=R_j[k], dT=dT[k], **pair_properties(mats[mi[k]], mats[mj[k]])), "C")
        assert (Q[k], e[k], t[k]) == pytest.approx((ref.Q, ref.e, ref.t_coll), rel=1e-6)


@pytest.mark.parametrize("path", ["exact", "fast"])
def test_collisions_beyond_the_models_range_are_flagged_as_collide_flags_them(path):
    """Run and post flag what ``collide`` flags (plugins.heat.validity): at 2000 m/s steel on
    steel indents deeper than its 1 mm radius; at 1 m/s not. The numbers are those of
    ``evaluate`` either way."""
    mats, m0 = [STEEL], np.zeros(3, int)
    R = np.full(3, 1e-3)
    v0 = np.array([1.0, 2000.0, 2000.0])
    R_j = np.array([1e-3, 1e-3, math.inf])                          # the last on a wall
    Q, e, t, flagged = evaluate_flagged("A", path, mats, m0, m0, R, R_j, v0, np.ones(3))
    assert flagged.tolist() == [False, True, True]
    ref = collide(2000.0, Pair(R1=1e-3, R2=1e-3, dT=1.0, **pair_properties(STEEL, STEEL)), "A")
    assert ref.delta_max > 1e-3
    assert np.concatenate([Q, e, t]) == pytest.approx(np.concatenate(evaluate("A", path, mats, m0, m0, R, R_j, v0,
                                                                             np.ones(3))), rel=1e-12)


def test_restitution_impulse_conserves_momentum_and_sets_separation():
    rng = np.random.default_rng(0)
    n = rng.normal(size=(5, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    v_i, v_j = rng.normal(size=(5, 3)), rng.normal(size=(5, 3))
    m_i, m_j = rng.uniform(1, 2, 5), np.array([1.0, 2.0, math.inf, 3.0, 1.0])
    v_j[2] = 0.0
    e, v0 = np.array([0.5, 0.9, 0.3, 1.7, 0.1]), rng.uniform(0.1, 1, 5)
    dv_i, dv_j, clipped = restitution_impulse(v_i, v_j, m_i, m_j, n, e, v0)
    assert clipped == 1
    sep = np.einsum("ij,ij->i", (v_i + dv_i) - (v_j + dv_j), n)
    assert sep == pytest.approx(np.minimum(e, 1) * v0, rel=1e-12)
    finite = np.isfinite(m_j)
    momentum = m_i[:, None] * dv_i + np.where(finite, m_j, 0)[:, None] * dv_j
    assert np.abs(momentum[finite]).max() < 1e-12
    assert np.all(dv_j[2] == 0)
