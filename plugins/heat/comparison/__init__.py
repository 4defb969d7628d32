"""Comparison models: the collision heat other tools compute, beside models A, B and C.

One module per model, file name = registry key; each defines ``MODEL``, a
``ComparisonModel`` whose ``heat(v0, pair, dem)`` returns, for arrays of normal impact
speeds v0 [m/s], a dict of arrays: Q [J] (> 0 from body 1 to body 2, at the pair's dT),
t_coll [s] (the contact time the model conducts over), e [-], which is NaN: a
comparison model is a side column and never gives restitution feedback, and delta_max [m],
the largest indentation of the contact it conducts through (flagged beyond the smaller
radius, as models A, B and C are: ``plugins.heat.batch.evaluate_flagged``).

Unlike A, B and C they are not a compression law plus a recovery law, so they have their
own registry. ``pair`` is a ``plugins.heat.Pair`` with the real material (fields may be
arrays broadcast against v0); ``dem`` a ``DemPair``, the DEM's softened contact, which only
models with ``needs_dem`` use.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from plugins.registry import Registry


@dataclass(frozen=True)
class DemPair:
    """The DEM's contact for one pair of materials, as LIGGGHTS sees it.

    Ystar: effective (softened) modulus, LIGGGHTS' Yeff = [(1-nu1^2)/Y1 + (1-nu2^2)/Y2]^-1 [Pa];
    restitution: the pair's coefficient of restitution [-];
    Ystar_original: the same with the real Young's moduli and the DEM's Poisson ratios, as
    heat/gran's ``area_correction`` forms it from ``youngsModulusOriginal`` [Pa].
    """

    Ystar: float
    restitution: float
    Ystar_original: float


@dataclass(frozen=True)
class ComparisonModel:
    name: str
    description: str
    needs_dem: bool
    heat: Callable          # heat(v0, pair, dem) -> dict(Q=..., t_coll=..., e=...)


COMPARISON = Registry(__name__, __path__, "comparison model")
"""{name: ComparisonModel}; ``COMPARISON.lookup(name)`` for a message naming the choices."""
