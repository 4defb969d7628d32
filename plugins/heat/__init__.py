"""Heat conducted between colliding particles: contact models A, B, C of Kosinski et al.
(2014), Int. J. Heat Mass Transfer 70, 674-687, with the heat of Sun & Chen (1988).

Public API (SI units throughout):
- ``Pair`` (and ``Pair.wall``): the two bodies; ``PAPER_SET`` the paper's parameters;
- ``collide(v0, pair, model)``: one collision by the exact path -> ``Collision``;
- ``MODELS``: the registry of contact models "A", "B", "C" (``plugins.registry.Registry``);
- ``plugins.heat.comparison.COMPARISON``: the comparison models (hertz, softened, ...);
  ``MODEL_NAMES`` every registered name of both.
"""
from plugins.heat.exact import Collision, collide
from plugins.heat.models import MODELS
from plugins.dem.hertz import effective_modulus
from plugins.heat.pair import PAPER_SET, Pair
from plugins.heat.comparison import COMPARISON

MODEL_NAMES = tuple(MODELS) + tuple(COMPARISON)

__all__ = ["Collision", "collide", "MODELS", "PAPER_SET", "Pair", "effective_modulus", "MODEL_NAMES"]
