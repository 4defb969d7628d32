"""Conduction through the gas gap between two particles (particle-fluid-particle), registered
by name: one module per model, file name = registry key = the value of ``[effects]
gap_conduction``. Each module defines ``MODEL``, a ``GapModel``."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from plugins.registry import Registry


@dataclass(frozen=True)
class GapModel:
    """Conduction through the gas between two spheres near each other or touching:
    ``conductance(pair, gas)`` -> H [W/K] per pair (``plugins.conduction.Pair``, ``Gas``), 0
    beyond the model's reach; heat into i at H (T_j - T_i). ``reach(r_max, gas)``: the largest
    gap [m] at which it conducts, for particles of radius at most r_max [m] (the neighbour
    search's cut-off). ``source``: the paper and the code it follows."""

    name: str
    conductance: Callable
    reach: Callable
    source: str


GAP = Registry(__name__, __path__, "gap conduction model")
"""{name: GapModel}; ``GAP.lookup(name)`` for a message naming the choices."""
