"""Physical facts every model must satisfy, checked on the exact path."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from plugins.heat import MODELS, Pair, collide
from plugins.heat.compression import compression_law

FLOATS = ("t_max", "delta_max", "a_max", "F_max", "delta_r", "delta_f", "R_bar", "t_r", "v1",
          "e", "t_coll", "Q", "Q_closed_form")
SPEEDS = (1e-4, 0.003, 0.02, 0.4, 1.5, 30.0)


def contact_force(pair, model, delta):
    """Compression force [N] at indentation delta [m], straight from eqs. (4), (8), (11), (12)."""
    law = compression_law(MODELS.lookup(model).compression, pair.b1, pair.b2, float(pair.log_constant))
    return float(law.force(delta / pair.delta_y)) * pair.F_y


@pytest.mark.parametrize("model", sorted(MODELS))
@pytest.mark.parametrize("v0", SPEEDS)
def test_compression_work_equals_impact_energy(paper_pair, model, v0):
    p = paper_pair
    c = collide(v0, p, model)
    breaks = [b * p.delta_y for b in (1.0, compression_law("Stronge", p.b1, p.b2, 3 * p.b1).x_p)
              if b * p.delta_y < c.delta_max]
    work, _ = quad(lambda d: contact_force(p, model, d), 0.0, c.delta_max, points=breaks or None,
                   epsabs=0, epsrel=1e-12, limit=200)
    assert work == pytest.approx(0.5 * p.mstar * v0**2, rel=1e-9)


@pytest.mark.parametrize("model", sorted(MODELS))
def test_rebound_energy_is_elastic_energy_of_recovery(paper_pair, model):
    # eqs. (22), (28): (1/2) m* v1^2 = (8/15) E* R_bar^1/2 delta_r^5/2
    for v0 in SPEEDS:
        c = collide(v0, paper_pair, model)
        stored = 8 / 15 * paper_pair.Estar * math.sqrt(c.R_bar) * c.delta_r**2.5
        assert 0.5 * paper_pair.mstar * c.v1**2 == pytest.approx(stored, rel=1e-12)


def _relative_gaps(a, b):
    return {k: abs(getattr(a, k) - getattr(b, k)) / max(abs(getattr(a, k)), abs(getattr(b, k)), 1e-300)
            for k in FLOATS}


@pytest.mark.parametrize("model", sorted(MODELS))
@pytest.mark.parametrize("onset", ["v_y", "v_p"])
def test_outputs_continuous_across_regime_onsets(paper_pair, model, onset):
    v = dict(zip(("v_y", "v_p"), paper_pair.onset_speeds()))[onset]
    below, above = collide(v * (1 - 1e-10), paper_pair, model), collide(v * (1 + 1e-10), paper_pair, model)
    gaps = _relative_gaps(below, above)
    gaps.pop("delta_f")                       # zero at v_y for model A: compared absolutely below
    gaps.pop("Q_closed_form")                 # switches from eq. (31), 0.87, to eq. (33), 0.88
    assert max(gaps.values()) < 1e-9, gaps
    assert abs(below.delta_f - above.delta_f) < 1e-9 * below.delta_max


@pytest.mark.parametrize("model", sorted(MODELS))
def test_swapping_bodies_changes_nothing(model):
    one = Pair(R1=1e-3, R2=3e-3, rho1=2500, rho2=7800, c1=800, c2=450, k1=1.0, k2=45.0)
    swapped = Pair(R1=3e-3, R2=1e-3, rho1=7800, rho2=2500, c1=450, c2=800, k1=45.0, k2=1.0)
    for v0 in SPEEDS:
        gaps = _relative_gaps(collide(v0, one, model), collide(v0, swapped, model))
        assert max(gaps.values()) < 1e-12, gaps


@pytest.mark.parametrize("model", sorted(MODELS))
def test_large_partner_tends_to_wall(model):
    wall = Pair.wall()
    for v0 in SPEEDS:
        far, at_wall = collide(v0, Pair(R2=2e-3 * 1e7), model), collide(v0, wall, model)
        gaps = _relative_gaps(far, at_wall)
        gaps.pop("delta_f")                   # a difference: compared against delta_max below
        assert max(gaps.values()) < 1e-6, gaps   # R*, m* differ from the wall's by 1e-7
        scale = max(at_wall.delta_max, abs(at_wall.delta_f))
        assert abs(far.delta_f - at_wall.delta_f) < 1e-6 * scale


@pytest.mark.parametrize("model", sorted(MODELS))
def test_heat_vanishes_without_and_scales_with_temperature_difference(paper_pair, model):
    for v0 in SPEEDS:
        assert collide(v0, paper_pair.replace(dT=0.0), model).Q == 0.0
        base = collide(v0, paper_pair.replace(dT=1.0), model).Q
        assert collide(v0, paper_pair.replace(dT=-37.5), model).Q == pytest.approx(-37.5 * base, rel=1e-13)


def test_models_A_and_C_share_contact_history_so_heat_and_duration(paper_pair):
    # Hertz recovery time and a(t) depend on R_bar*delta_r = a_max^2 only, which both keep:
    # A and C differ in e alone.
    for v0 in SPEEDS:
        A, C = collide(v0, paper_pair, "A"), collide(v0, paper_pair, "C")
        assert C.t_coll == pytest.approx(A.t_coll, rel=1e-12)
        assert C.Q == pytest.approx(A.Q, rel=1e-9)


@pytest.mark.parametrize("model", sorted(MODELS))
def test_history_is_consistent(paper_pair, model):
    c = collide(0.7, paper_pair, model, history=True)
    h = c.history
    assert np.all(np.diff(h["t"]) >= 0)
    assert h["t"][0] == pytest.approx(0.0, abs=1e-12 * c.t_coll)
    assert h["t"][-1] == pytest.approx(c.t_coll, rel=1e-12)
    assert h["delta"].max() == pytest.approx(c.delta_max, rel=1e-12)
    assert h["a"].max() == pytest.approx(c.a_max, rel=1e-12)
    assert h["a"][-1] == pytest.approx(0.0, abs=1e-6 * c.a_max)
    assert h["delta"][-1] == pytest.approx(c.delta_f, abs=1e-9 * c.delta_max)
