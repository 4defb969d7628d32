"""The fast path: self-similarity it rests on, accuracy over the stated range, array pairs."""
import numpy as np
import pytest

from plugins.heat import MODELS, Pair, collide
from plugins.heat.fast import collide_fast


@pytest.mark.parametrize("model", sorted(MODELS))
def test_outputs_depend_on_v0_over_vy_b1_b2_only(model):
    # Two pairs differing in every size and material, at the same v0/v_y: same dimensionless outputs.
    a = Pair()
    b = Pair(R1=7e-5, R2=3e-4, rho1=2500, rho2=1100, Estar=3e9, Y=4e7, c1=900, c2=1500, k1=0.3, k2=2.0)
    for v_hat in (0.01, 1.7, 60.0, 3e4):
        ca, cb = collide(v_hat * a.v_y, a, model), collide(v_hat * b.v_y, b, model)
        assert ca.e == pytest.approx(cb.e, rel=1e-10)
        assert ca.delta_max / a.delta_y == pytest.approx(cb.delta_max / b.delta_y, rel=1e-10)
        assert ca.t_coll / a.t_y == pytest.approx(cb.t_coll / b.t_y, rel=1e-10)
        assert ca.Q / a.Q_scale == pytest.approx(cb.Q / b.Q_scale, rel=1e-10)


@pytest.mark.parametrize("model", sorted(MODELS))
def test_fast_within_1e6_of_exact_over_stated_range(paper_pair, model):
    rng = np.random.default_rng(12345)
    v0 = paper_pair.v_y * np.exp(rng.uniform(np.log(1e-3), np.log(1e5), 150))
    fast = collide_fast(v0, paper_pair, model)
    worst = {k: 0.0 for k in ("e", "t_coll", "delta_max", "Q")}
    for j, v in enumerate(v0):
        c = collide(v, paper_pair, model)
        for k in worst:
            worst[k] = max(worst[k], abs(fast[k][j] / getattr(c, k) - 1))
    assert max(worst.values()) < 1e-6, worst


def test_fast_accepts_one_pair_per_collision():
    R1 = np.array([1e-4, 1e-3, 5e-3])
    dT = np.array([10.0, -20.0, 0.0])
    pairs = Pair(R1=R1, dT=dT)
    v0 = np.array([0.01, 0.5, 3.0])
    fast = collide_fast(v0, pairs, "C")
    for j in range(3):
        c = collide(v0[j], Pair(R1=R1[j], dT=dT[j]), "C")
        assert fast["Q"][j] == pytest.approx(c.Q, rel=1e-6, abs=1e-300)
        assert fast["e"][j] == pytest.approx(c.e, rel=1e-6)


def test_fast_falls_back_to_exact_outside_tables(paper_pair):
    v0 = np.array([1e-15, 1e10]) * paper_pair.v_y
    fast = collide_fast(v0, paper_pair, "A")
    for j, v in enumerate(v0):
        assert fast["Q"][j] == pytest.approx(collide(v, paper_pair, "A").Q, rel=1e-9)


def test_fast_rejects_unknown_outputs(paper_pair):
    with pytest.raises(ValueError, match="unknown outputs"):
        collide_fast([1.0], paper_pair, "A", outputs=("e", "heat"))


@pytest.mark.parametrize("edited", ["heat/models/A.py", "dem/hertz.py"])
def test_table_cache_key_changes_when_any_plugin_file_changes(tmp_path, edited):
    """The tables depend on every file of the heat plugin and on the DEM plugin's Hertz
    constants: an edit of a model in models/ (not only of the integrators) or of
    plugins/dem/hertz.py gives another source digest, hence another cache key, so a stale
    table is never read."""
    import shutil
    from pathlib import Path
    from plugins.heat import fast, table_cache
    root = tmp_path / "plugins"
    for part in ("heat", "dem"):
        shutil.copytree(Path(fast.__file__).parents[1] / part, root / part, ignore=shutil.ignore_patterns("__pycache__"))
    before = table_cache.source_digest.__wrapped__(root)
    assert table_cache.source_digest.__wrapped__(root) == before
    (root / edited).write_text((root / edited).read_text() + "\n# edited\n")
    assert table_cache.source_digest.__wrapped__(root) != before


def test_the_hertz_constant_written_out_is_scipys_beta_to_the_last_digit():
    """K_HERTZ = 0.4 B(0.4, 0.5), written out so that a run need not import scipy.special: the
    same double as scipy computes, so results do not change by a bit."""
    from scipy.special import beta

    from plugins.dem.hertz import K_HERTZ
    assert K_HERTZ == float(0.4 * beta(0.4, 0.5))
