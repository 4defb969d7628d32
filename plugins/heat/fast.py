"""The fast path: arrays of collisions through tables built once per (model, b1, b2, c).

Self-similarity (checked in tests/unit/test_fast.py): in the units of ``compression.py``
(delta_y, a_y, F_y, v_y, t_y = delta_y/v_y and Pair.Q_scale) every output of a model depends
only on v0/v_y, b1, b2 and the constant c of eq. (8). So each model needs one table per
(b1, b2, c), over u = ln(v0/v_y), of ln x_max, ln t_max, ln t_coll, ln e and ln Q.

The outputs are smooth in u except at the onsets of the elastic-plastic (u = 0) and fully
plastic (u = u_p) ranges, where they go like (u - u_onset)^(1/2). The table coordinate
q removes that:  q = u/lambda (u <= 0, where everything is a power law, linear in u),
q = u^(1/2) (0 < u <= u_p), q = u_p^(1/2) + (u - u_p)^(1/2) (u > u_p); model B has no
regimes and uses q = u. On a uniform q grid with the onsets on nodes, a not-a-knot cubic
spline per range (scipy) gives a relative error below 1e-8 (measured by
tools/bench_fast.py). Evaluation gathers the 4 spline coefficients of each column asked for
and takes a Horner step. Speeds outside [V_MIN, V_MAX] v_y go through the exact path.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from plugins.heat import exact, table_cache
from plugins.heat.compression import compression_law
from plugins.heat.models import MODELS
from plugins.heat.pair import Pair
from plugins.heat.recovery import RECOVERY_LAWS

V_MIN, V_MAX = 1e-12, 1e12      # table range of v0/v_y
H = 0.01                         # q spacing of the nodes for models with regimes (A, C)
H_SMOOTH = 0.1                   # u spacing for model B, smooth in u = ln(v0/v_y)
COLUMNS = ("x_max", "t_max", "t_coll", "e", "Q")
CHUNK = 32768                    # collisions per block (measured best of 4096..65536)


class Table:
    """Cubic tables of the dimensionless outputs of one model against v0/v_y."""

    def __init__(self, model: str, b1: float, b2: float, c: float, spacing: float | None = None):
        """``spacing``: node spacing in q (default H for A and C, H_SMOOTH for B); for
        studies of table resolution (tools/bench_accuracy.py)."""
        self.model, self.b1, self.b2, self.c = model, b1, b2, c
        law = compression_law(MODELS.lookup(model).compression, b1, b2, c)
        self.u_min, self.u_max = math.log(V_MIN), math.log(V_MAX)
        self.staged = hasattr(law, "v_hat_p")
        if self.staged:
            h = H if spacing is None else spacing
            self.u_p = math.log(law.v_hat_p)
            n_ep = max(4, math.ceil(math.sqrt(self.u_p) / h))
            h = math.sqrt(self.u_p) / n_ep
            n_el = 8
            self.lam = -self.u_min / (n_el * h)
            n_fp = math.ceil(math.sqrt(self.u_max - self.u_p) / h) + 1
            segments = [np.arange(-n_el, 1) * h, np.arange(0, n_ep + 1) * h,
                        (n_ep + np.arange(0, n_fp + 1)) * h]
        else:
            h = H_SMOOTH if spacing is None else spacing
            n = math.ceil((self.u_max - self.u_min) / h)
            segments = [self.u_min + np.arange(0, n + 1) * h]
        self.h, self.q0 = h, segments[0][0]
        from scipy.interpolate import CubicSpline   # here: only a table's build needs it (0.2 s to import)

        coefs = []
        for q in segments:
            values = np.array([self._node(float(v)) for v in np.exp(self.u_of_q(q))])
            coefs.append(CubicSpline(q, values, bc_type="not-a-knot").c)   # (4, n, k)
        self.coef = np.ascontiguousarray(np.concatenate(coefs, axis=1).transpose(2, 0, 1))  # (k, 4, n)
        self.n = self.coef.shape[2]

    def _node(self, v: float) -> list[float]:
        d = exact.solve(self.model, v, self.b1, self.b2, self.c)
        return [math.log(d["x_max"]), math.log(d["t_max"]), math.log(d["t_max"] + d["t_r"]),
                math.log(d["v1"] / v), math.log(d["Q"])]

    def u_of_q(self, q):
        q = np.asarray(q, float)
        if not self.staged:
            return q
        sp = math.sqrt(self.u_p)
        return np.where(q <= 0, q * self.lam, np.where(q <= sp, q * q, self.u_p + (q - sp) ** 2))

    def q_of_u(self, u):
        """Table coordinate of u = ln(v0/v_y), branch-free (it is the hot path)."""
        if not self.staged:
            return u
        fp = u > self.u_p
        q = np.maximum(u, 0.0)
        q -= fp * self.u_p
        np.sqrt(q, out=q)
        q += fp * math.sqrt(self.u_p)
        q += np.minimum(u, 0.0) * (1.0 / self.lam)
        return q

    def lookup(self, v_hat, columns):
        """Tabulated values (ln of COLUMNS[j]) for each v0/v_y, as {j: array} for j in columns."""
        pos = self.q_of_u(np.log(v_hat))
        pos -= self.q0
        pos *= 1.0 / self.h
        i = pos.astype(np.intp)
        np.clip(i, 0, self.n - 1, out=i)
        t = pos - i
        t *= self.h
        out = {}
        for j in columns:
            c = self.coef[j]
            y = c[0].take(i)
            for d in (1, 2, 3):
                y *= t
                y += c[d].take(i)
            out[j] = y
        return out


@lru_cache(maxsize=32)
def table(model: str, b1: float, b2: float, c: float, spacing: float | None = None) -> Table:
    """The table of ``model`` for (b1, b2, c): from memory, else from the disk cache
    (``plugins.heat.table_cache``: COLLHEAT_CACHE, default ~/.cache/collheat), else built (a
    few seconds) and cached. ``spacing`` other than None (the default H / H_SMOOTH) builds a
    table of that node spacing, cached under its own key."""
    ident = (model, b1, b2, c) if spacing is None else (model, b1, b2, c, float(spacing))
    tab = Table.__new__(Table)
    state = table_cache.load(model, ident)
    if state is not None:
        tab.__dict__.update(state)
        return tab
    tab = Table(model, b1, b2, c, spacing)
    table_cache.save(model, ident, tab.__dict__)
    return tab


PAIR_FIELDS = ("R1", "R2", "rho1", "rho2", "Estar", "Y", "c1", "c2", "k1", "k2", "dT")
SCALES = ("v_y", "delta_y", "t_y", "a_y", "F_y", "Rstar", "sigma", "dT", "Q_scale")
REGIMES = ("elastic", "elastic-plastic", "fully plastic")


def collide_fast(v0, pair: Pair | None = None, model: str = "A", outputs=exact.OUTPUT_KEYS) -> dict:
    """Many head-on collisions at normal impact speeds v0 [m/s] (array) by table lookup.

    ``pair`` may hold arrays (one pair per collision, broadcast against v0) except b1, b2 and
    c_log, which must be scalars. Returns a dict of arrays with the keys of ``outputs`` (the
    keys of ``Collision``, SI units; "regime" as 0 elastic, 1 elastic-plastic, 2 fully
    plastic; "flags" as a bit mask, 1 negative residual indentation, 2 e > 1). Asking only
    for what is needed (e.g. "e", "Q") is fastest.
    Accuracy: relative error below 1e-6 against the exact path (tools/bench_fast.py).
    """
    pair = Pair() if pair is None else pair
    v0 = exact.check_speed(v0)
    unknown = set(outputs) - set(exact.OUTPUT_KEYS)
    if unknown:
        raise ValueError(f"unknown outputs {sorted(unknown)}; choices: {', '.join(exact.OUTPUT_KEYS)}")
    if any(np.ndim(getattr(pair, k)) for k in ("b1", "b2")):
        raise ValueError("collide_fast: b1 and b2 must be scalars (group collisions by material pair)")
    tab = table(MODELS.lookup(model).name, float(pair.b1), float(pair.b2), float(pair.log_constant))
    shape = np.broadcast_shapes(v0.shape, *(np.shape(getattr(pair, f)) for f in PAIR_FIELDS))
    n = math.prod(shape)
    flat = lambda a: (np.asarray(a, float) if np.ndim(a) == 0 else
                      np.asarray(a, float).ravel() if np.shape(a) == shape else np.broadcast_to(a, shape).ravel())
    v0 = np.broadcast_to(v0, shape).ravel()
    sc = {k: flat(getattr(pair, k)) for k in SCALES}
    out = {k: np.empty(n) for k in outputs}
    for lo in range(0, n, CHUNK):
        s = slice(lo, lo + CHUNK)
        chunk = {k: (a if a.ndim == 0 else a[s]) for k, a in sc.items()}
        _fill(out, s, tab, v0[s], chunk)
    for j in np.flatnonzero((v0 / sc["v_y"] < V_MIN) | (v0 / sc["v_y"] > V_MAX)):
        one = pair.replace(**{f: float(flat(getattr(pair, f)).ravel()[j] if np.ndim(getattr(pair, f))
                                       else getattr(pair, f)) for f in PAIR_FIELDS})
        col = exact.collide(float(v0[j]), one, model)
        for k in out:
            out[k][j] = (REGIMES.index(col.regime) if k == "regime" else
                         _flag_bits("negative_residual_indentation" in col.flags,
                                    "restitution_above_one" in col.flags) if k == "flags" else
                         getattr(col, k))
    return {k: a.reshape(shape) for k, a in out.items()}


def _flag_bits(negative_residual, e_above_one):
    return 1 * negative_residual | 2 * e_above_one


NEEDS = dict(delta_max=(0, "delta_y"), t_max=(1, "t_y"), t_coll=(2, "t_y"), e=(3, None),
             Q=(4, "Q_scale"))


def _fill(out, s, tab, v0, sc):
    """Outputs of one block of collisions into out[...][s]."""
    derived_keys = out.keys() - NEEDS.keys()
    columns = {NEEDS[k][0] for k in out.keys() & NEEDS.keys()} | ({0, 1, 2, 3} if derived_keys else set())
    L = tab.lookup(v0 / sc["v_y"], sorted(columns))
    for y in L.values():
        np.exp(y, out=y)
    for k in out.keys() & NEEDS.keys():
        j, scale = NEEDS[k]
        if scale is None:
            out[k][s] = L[j]
        else:
            np.multiply(L[j], sc[scale], out=out[k][s])
    if not derived_keys:
        return
    m = MODELS.lookup(tab.model)
    law = compression_law(m.compression, tab.b1, tab.b2, tab.c)
    x, e, t_y = L[0], L[3], sc["t_y"]
    A = law.a2(x)
    s_r, rho = RECOVERY_LAWS[m.recovery](law, x)
    a_max = np.sqrt(A) * sc["a_y"]
    regime = np.where(x <= 1.0, 0, np.where(x <= law.x_p, 1, 2)) if tab.staged else np.full(x.shape, 2)
    derived = dict(
        a_max=lambda: a_max, F_max=lambda: law.force(x) * sc["F_y"],
        delta_r=lambda: s_r * sc["delta_y"], delta_f=lambda: (x - s_r) * sc["delta_y"],
        R_bar=lambda: rho * sc["Rstar"], regime=lambda: regime, v1=lambda: e * v0,
        t_r=lambda: (L[2] - L[1]) * t_y,
        Q_closed_form=lambda: exact.closed_form_heat(a_max, L[2] * t_y, regime == 0,
                                                     sc["dT"], sc["sigma"]),
        flags=lambda: _flag_bits(x - s_r < -exact.FLAG_TOL * x, e > 1.0 + exact.FLAG_TOL))
    for k in derived_keys:
        out[k][s] = derived[k]()
