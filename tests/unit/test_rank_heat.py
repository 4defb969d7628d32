"""One rank's part of a harvest (pyhost.effects.rank_heat.on_rank), without engines: the rank's
atoms as arrays, its events as the recorder hands them over, one rank (comm None)."""
import numpy as np
from conftest import steel_material

from plugins.heat.batch import evaluate
from plugins.heat.exchange import WALL_BASE
from pyhost.effects.rank_heat import RankHeat, on_rank
from pyhost.engines.atoms import Atoms
from pyhost.engines.events import BEGIN, END, EVENT


class Events:
    def __init__(self, rows):
        self.ev = np.zeros(len(rows), EVENT)
        for r, (kind, step, i, j, vn, moved) in enumerate(rows):
            e = self.ev[r]
            e["kind"], e["step"], e["i"], e["j"], e["vn"], e["moved"] = kind, step, i, j, vn, moved
            e["wall"] = j >= WALL_BASE

    def take(self):
        return self.ev


def test_a_rank_moves_its_collisions_in_order_and_leaves_the_rest_to_rank_0():
    steel = steel_material()
    R = np.array([1e-3, 1e-3, 2e-3, 1e-3])
    mass = 7800.0 * 4 / 3 * np.pi * R ** 3
    T = np.array([400.0, 300.0, 350.0, 0.0])        # atom 4: inserted, not seen by rank 0 yet
    atoms = Atoms(np.array([1, 2, 3, 4]), None, None, R, mass, np.array([1, 1, 1, 1]), T)
    wall = WALL_BASE + 0
    events = Events([(BEGIN, 12, 2, 3, 0.3, False), (BEGIN, 10, 1, 2, 0.5, False), (BEGIN, 12, 1, wall, 0.4, False),
                     (BEGIN, 15, 3, 4, 0.2, False), (END, 20, 1, 2, 0.0, False), (BEGIN, 30, 2, 3, 0.1, True),
                     (BEGIN, 31, 1, 3, 0.0, False)])
    seen = np.array([False, True, True, True])      # by id: 1-3 seen
    setup = RankHeat([steel], np.array([-1, 0]), np.array([steel.heat_capacity]), ("A",), "exact",
                     np.array([500.0]), np.array([-1]), (0.0, 0, 1e-6), np.packbits(seen), len(seen), np.array([np.nan, 320.0]))
    got = on_rank(atoms, events, None, setup)

    # the reference: atom 4 at its material's 320 K, then one collision after the other in
    # the order (step, walls last, ids), each G = Q per kelvin of model A, q = G (T_i - T_j)
    ref = np.array([400.0, 300.0, 350.0, 320.0])
    C = mass * steel.heat_capacity
    order = [(10, 0, 1, 0.5), (12, 1, 2, 0.3), (12, 0, None, 0.4), (15, 2, 3, 0.2)]
    Q = []
    for _, a, b, v in order:
        R_b = np.inf if b is None else R[b]
        G = evaluate("A", "exact", [steel], np.array([0]), np.array([0]), R[[a]], np.array([R_b]), np.array([v]),
                     np.ones(1))[0][0]
        q = G * (ref[a] - (500.0 if b is None else ref[b]))
        ref[a] -= q / C[a]
        if b is not None:
            ref[b] += q / C[b]
        Q.append(q)
    assert np.allclose(T, ref, rtol=0, atol=1e-12)
    assert list(got["step"]) == [10, 12, 12, 15]
    assert list(got["cols"]["i"]) == [1, 2, 1, 3] and list(got["cols"]["wall"]) == [0, 0, 1, 0]
    assert np.allclose(got["cols"]["Q"], Q, rtol=1e-12, atol=0)
    assert got["still"] == 1                                   # (1, 3) began without closing in
    assert list(got["events"]["step"]) == [30]                # the contact that changed rank: rank 0's
    assert list(got["new"][0]) == [4] and got["new"][4][0] == 0.0     # atom 4 came in at 0 K, set to 320 K
    assert sorted(got["ids"].tolist()) == [1, 2, 3, 4]
    assert np.allclose(got["T_after"], T[got["ids"] - 1])
