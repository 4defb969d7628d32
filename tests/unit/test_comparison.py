"""Comparison models against independent evaluations: eqs. (31)-(32) for ``hertz``, a direct
time integration of LIGGGHTS' contact law and heat/gran's conductance for ``softened``."""
import math

import numpy as np
import pytest
from conftest import steel_material
from scipy.integrate import quad, solve_ivp
from scipy.special import betainc

from plugins.heat import MODEL_NAMES, Pair, collide
from plugins.heat.comparison import COMPARISON, DemPair
from plugins.heat.batch import dem_pair, evaluate, pair_properties, side_heat
from pyhost.schema import DemContact, Material

STEEL = steel_material()
ALU = Material(2700.0, 70e9, 0.33, 100e6, 900.0, 200.0, DemContact(youngs_modulus=5e7, restitution=0.6,
                                                                   poisson_ratio=0.25))


def test_hertz_matches_closed_form_of_eqs_31_32():
    # eq. (3) for a Hertz history: Q = c31 pi a_max^2 dT t_coll^(1/2) / sigma, with each ring's
    # contact time t_coll (1 - I(y^(5/2); 2/5, 1/2)) at a^2 = y a_max^2
    # (y = 1 - s^2 takes the square root off the end y = 1)
    c31 = 2 / math.sqrt(math.pi) * quad(lambda s: 2 * s * math.sqrt(1 - betainc(0.4, 0.5, (1 - s * s) ** 2.5)),
                                        0, 1, epsabs=1e-13, epsrel=1e-13, limit=200)[0]
    c32 = 2 * 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9) * (15 / 16) ** 0.4
    assert c31 == pytest.approx(0.87093, abs=5e-6) and c32 == pytest.approx(2.8683, abs=5e-5)
    v0 = np.array([1e-4, 0.01, 0.5, 3.0, 40.0])
    for pair in (Pair(), Pair(R1=1e-3, R2=3e-3, rho2=2500.0, k2=1.0, c2=840.0, dT=-20.0), Pair.wall()):
        out = COMPARISON["hertz"].heat(v0, pair)
        d_max = (15 * pair.mstar * v0**2 / (16 * pair.Estar * math.sqrt(pair.Rstar))) ** 0.4
        t_coll = c32 * (pair.mstar**2 / (pair.Rstar * pair.Estar**2 * v0)) ** 0.2
        Q = c31 * math.pi * pair.Rstar * d_max * pair.dT * np.sqrt(t_coll) / pair.sigma
        assert out["t_coll"] == pytest.approx(t_coll, rel=1e-10)
        assert out["Q"] == pytest.approx(Q, rel=1e-10)
        assert np.all(np.isnan(out["e"]))


def test_hertz_is_model_A_below_yield():
    pair = Pair()
    v0 = 0.5 * pair.v_y
    assert COMPARISON["hertz"].heat(v0, pair)["Q"] == pytest.approx(collide(v0, pair, "A").Q, rel=1e-10)


def lens_area(delta, R1, R2):
    """heat/gran's area as fix_heat_gran_conduction.cpp writes it (wall: fix_wall_gran.cpp)."""
    if math.isinf(R2):
        return math.pi * (R1**2 - (R1 - delta) ** 2)
    r = R1 + R2 - delta
    return -math.pi / 4 * ((r - R1 - R2) * (r + R1 - R2) * (r - R1 + R2) * (r + R1 + R2)) / r**2


def kratos_radius(delta, R1, R2):
    """Kratos' ThermalSphericParticle::ComputeContactRadius at centre distance d."""
    if math.isinf(R2):
        return math.sqrt(R1**2 - (R1 - delta) ** 2)
    d = R1 + R2 - delta
    return math.sqrt(abs(R1**2 - ((R1**2 - R2**2 + d**2) / (2 * d)) ** 2))


def direct_heat(v0, pair, dem, name):
    """Integrate m* delta'' = -F (normal_model_hertz.h) with dQ/dt = h(delta) dT, to release:
    heat/gran's h (softened, softened_corrected) or Kratos' 4 k_eff R_c with Zhou's R_c (zhou)."""
    beta = math.log(dem.restitution) / math.sqrt(math.log(dem.restitution) ** 2 + math.pi**2) \
        if dem.restitution < 1 else 0.0
    R, m = pair.Rstar, pair.mstar
    h = 4 * pair.k1 * pair.k2 / (pair.k1 + pair.k2)
    ratio = (dem.Ystar / dem.Ystar_original) ** (2 / 3) if name == "softened_corrected" else 1.0
    zhou = (dem.Ystar / dem.Ystar_original) ** 0.2

    def rhs(t, y):
        d = max(y[0], 0.0)
        Sn = 2 * dem.Ystar * math.sqrt(R * d)
        F = 4 / 3 * dem.Ystar * math.sqrt(R * d) * d - 2 * math.sqrt(5 / 6) * beta * math.sqrt(Sn * m) * y[1]
        if name == "zhou":
            return [y[1], -F / m, h * kratos_radius(d, pair.R1, pair.R2) * zhou * pair.dT]
        return [y[1], -F / m, h * math.sqrt(lens_area(ratio * d, pair.R1, pair.R2)) * pair.dT]

    release = lambda t, y: y[0]
    release.terminal, release.direction = True, -1
    t_end = 20 * (m**2 / (dem.Ystar**2 * R * v0)) ** 0.2
    sol = solve_ivp(rhs, (0, t_end), [0.0, v0, 0.0], method="LSODA", rtol=1e-11, atol=[1e-16, 1e-12, 1e-22],
                    events=release)
    return sol.y_events[0][0][2], sol.t_events[0][0]


@pytest.mark.parametrize("name", ["softened", "softened_corrected", "zhou"])
@pytest.mark.parametrize("pair, dem", [
    (Pair(R1=2e-3, R2=2e-3, k1=20.0, k2=20.0, dT=100.0), DemPair(5e6, 0.9, 100e9)),
    (Pair(R1=1e-3, R2=3e-3, k1=200.0, k2=1.0, rho2=2500.0, dT=-30.0), DemPair(1e8, 0.5, 40e9)),
    (Pair.wall(R1=2.5e-3, k1=45.0, k2=45.0, dT=1.0), DemPair(1e7, 1.0, 110e9)),
])
def test_softened_matches_direct_time_integration(name, pair, dem):
    v0 = np.array([0.05, 0.5, 5.0])
    out = COMPARISON[name].heat(v0, pair, dem)
    for k, v in enumerate(v0):
        Q, t_c = direct_heat(v, pair, dem, name)
        assert out["t_coll"][k] == pytest.approx(t_c, rel=1e-7)
        assert out["Q"][k] == pytest.approx(Q, rel=1e-6)


def test_area_correction_scales_heat_by_a_third_power_of_the_modulus_ratio():
    # area ~ delta for overlaps << R, so h ~ delta^(1/2): Q ratio -> (Y*/Y*_orig)^(1/3)
    pair, dem = Pair(), DemPair(1e7, 0.8, 1e11)
    plain, corr = (COMPARISON[n].heat(1e-4, pair, dem)["Q"] for n in ("softened", "softened_corrected"))
    assert corr / plain == pytest.approx((1e7 / 1e11) ** (1 / 3), rel=1e-5)


def test_dem_pair_as_liggghts_forms_it():
    d = dem_pair(STEEL, ALU)
    assert d.Ystar == pytest.approx(1 / ((1 - 0.09) / 1e7 + (1 - 0.0625) / 5e7))
    assert d.Ystar_original == pytest.approx(1 / ((1 - 0.09) / 210e9 + (1 - 0.0625) / 70e9))
    assert d.restitution == pytest.approx(0.75)


def test_evaluate_takes_comparison_models_and_rejects_unknown_names():
    mats = [STEEL, ALU]
    mi, mj = np.array([0, 1]), np.array([1, 0])
    R_i, R_j, v0, dT = np.array([1e-3, 2e-3]), np.array([2e-3, math.inf]), np.array([0.3, 1.0]), np.array([5.0, 2.0])
    Q, e, t = evaluate("softened", "fast", mats, mi, mj, R_i, R_j, v0, dT)
    for k in range(2):
        pair = Pair(R1=R_i[k], R2=R_j[k], dT=dT[k], **pair_properties(mats[mi[k]], mats[mj[k]]))
        ref = COMPARISON.lookup("softened").heat(v0[k], pair, dem_pair(mats[mi[k]], mats[mj[k]]))
        assert (Q[k], t[k]) == pytest.approx((float(ref["Q"]), float(ref["t_coll"])), rel=1e-12)
    assert np.all(np.isnan(e))
    with pytest.raises(ValueError) as err:
        evaluate("Z", "fast", mats, mi, mj, R_i, R_j, v0, dT)
    assert all(name in str(err.value) for name in MODEL_NAMES)


@pytest.mark.parametrize("model", ["A", "B", "C"])
def test_restitution_of_contact_models_unchanged_by_side_models(model):
    mats = [STEEL, ALU]
    rng = np.random.default_rng(1)
    n = 50
    mi, mj = rng.integers(0, 2, n), rng.integers(0, 2, n)
    R_i, R_j = rng.uniform(1e-3, 3e-3, n), np.where(rng.random(n) < 0.2, math.inf, rng.uniform(1e-3, 3e-3, n))
    v0, ones = rng.uniform(0.01, 3.0, n), np.ones(n)
    alone = evaluate(model, "fast", mats, mi, mj, R_i, R_j, v0, ones)
    side = side_heat([m for m in MODEL_NAMES if m != model], "fast", mats, mi, mj, R_i, R_j, v0, ones)
    again = evaluate(model, "fast", mats, mi, mj, R_i, R_j, v0, ones)
    assert set(side) == set(MODEL_NAMES) - {model}
    for a, b in zip(alone, again):
        assert np.array_equal(a, b)
    # and e is the plugin's own, collision by collision
    for k in range(0, n, 10):
        pair = Pair(R1=R_i[k], R2=R_j[k], dT=1.0, **pair_properties(mats[mi[k]], mats[mj[k]]))
        assert alone[1][k] == pytest.approx(collide(v0[k], pair, model).e, rel=1e-6)
