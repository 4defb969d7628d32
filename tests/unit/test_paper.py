"""The paper's own statements (Kosinski et al. 2014), to the digits it prints."""
import math

import pytest
from scipy.optimize import brentq
from scipy.special import beta

from plugins.heat import collide


def test_yield_onset_speed_is_printed_value(paper_pair):
    # sec. 6: v_y = 0.0055 m/s
    assert paper_pair.v_y == pytest.approx(0.0055, abs=5e-5)


def test_fully_plastic_onset_reached_at_delta_p(paper_pair):
    # v_p is where compression just reaches delta_p (eq. 10) with mean pressure b2*Y.
    # The paper prints 1.123 m/s; this implementation gives 1.1017 m/s (see README).
    v_y, v_p = paper_pair.onset_speeds()
    c = collide(v_p, paper_pair, "A")
    X_p = math.exp(3 * (paper_pair.b2 - paper_pair.b1))                        # eq. (9)
    assert c.delta_max == pytest.approx(paper_pair.delta_y * (X_p + 1) / 2, rel=1e-10)
    p_mean = c.F_max / (math.pi * c.a_max**2)
    assert p_mean == pytest.approx(paper_pair.b2 * paper_pair.Y, rel=1e-10)
    assert 1.05 < v_p < 1.15


@pytest.mark.parametrize("model", ["A", "C"])
def test_onset_speeds_exactly(paper_pair, model):
    # a speed of exactly v_y or v_p (as computed) lands on the regime boundary, eqs. (6), (10)
    v_y, v_p = paper_pair.onset_speeds()
    X_p = math.exp(3 * (paper_pair.b2 - paper_pair.b1))
    assert collide(v_y, paper_pair, model).delta_max == pytest.approx(paper_pair.delta_y, rel=1e-12)
    at_p = collide(v_p, paper_pair, model)
    assert at_p.delta_max == pytest.approx(paper_pair.delta_y * (X_p + 1) / 2, rel=1e-12)
    assert at_p.regime == "elastic-plastic"


def test_recovery_ratios_tend_to_b1_over_b2(paper_pair):
    # eqs. (41)-(42): r2 = delta_r,S/delta_r,J and r3 = R_bar,J/R_bar,S -> b1/b2 = 0.393
    A, B = collide(1e3, paper_pair, "A"), collide(1e3, paper_pair, "B")
    limit = paper_pair.b1 / paper_pair.b2
    assert A.delta_r / B.delta_r == pytest.approx(limit, rel=1e-4)
    assert B.R_bar / A.R_bar == pytest.approx(limit, rel=1e-4)
    # and they approach it from above as speed grows (eq. 41: factor (2 - delta_y/delta_max)^1/2 / 2^1/2)
    slow_A, slow_B = collide(0.05, paper_pair, "A"), collide(0.05, paper_pair, "B")
    assert abs(slow_A.delta_r / slow_B.delta_r - limit) > abs(A.delta_r / B.delta_r - limit)


def test_model_B_compression_time_independent_of_speed(paper_pair):
    # eq. (15): t_max = (pi/2) (m*/(2 pi b2 Y R*))^1/2 whatever v0
    p = paper_pair
    expected = 0.5 * math.pi * math.sqrt(p.mstar / (2 * math.pi * p.b2 * p.Y * p.Rstar))
    for v in (1e-6, 1e-3, 0.1, 10.0, 1e3):
        assert collide(v, p, "B").t_max == pytest.approx(expected, rel=1e-12)


def test_model_C_recovery_exceeds_compression_below_about_5_delta_y(paper_pair):
    # eq. (38): delta_r/delta_max > 1 for delta_max/delta_y below ~5.0
    ratio = lambda v: (lambda c: c.delta_r / c.delta_max - 1)(collide(v, paper_pair, "C"))
    v_cross = brentq(ratio, 1.01 * paper_pair.v_y, 1.0, xtol=1e-12)
    x_cross = collide(v_cross, paper_pair, "C").delta_max / paper_pair.delta_y
    assert x_cross == pytest.approx(5.0, abs=0.05)
    assert ratio(0.5 * v_cross) > 0 > ratio(2 * v_cross)


def test_elastic_impact_prefactors(paper_pair):
    p = paper_pair
    c = collide(0.3 * p.v_y, p, "A")
    assert c.regime == "elastic"
    # eq. (31): Q = 0.87 pi a_max^2 dT t_coll^1/2 / sigma
    prefactor = c.Q / (math.pi * c.a_max**2 * p.dT * math.sqrt(c.t_coll) / p.sigma)
    assert prefactor == pytest.approx(0.87, abs=0.005)
    # eq. (32): t_coll = 2.86 (m*^2/(E*^2 R* v0))^1/5 (printed truncated; exact 2.8683)
    constant = c.t_coll / (p.mstar**2 / (p.Estar**2 * p.Rstar * c.v0)) ** 0.2
    assert constant == pytest.approx(2.86, abs=0.01)
    exact_constant = 2 * 0.4 * beta(0.4, 0.5) * (15 / 16) ** 0.4
    assert constant == pytest.approx(exact_constant, rel=1e-10)


def test_compression_of_A_and_C_coincide(paper_pair):
    # sec. 6: "Models A and C lead to the same results" for compression (Figs. 2, 3)
    for v in (0.003, 0.05, 2.0):
        A, C = collide(v, paper_pair, "A"), collide(v, paper_pair, "C")
        assert (A.t_max, A.delta_max, A.a_max, A.F_max) == (C.t_max, C.delta_max, C.a_max, C.F_max)
