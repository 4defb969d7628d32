"""Nusselt correlations registered by name: one module per correlation, file name = registry
key = the value of ``[effects] convection``. Each module defines ``MODEL``, a ``Correlation``."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from plugins.registry import Registry


@dataclass(frozen=True)
class Correlation:
    """A gas-particle Nusselt correlation: ``nusselt(re, pr, alpha)`` -> Nu (-), vectorised,
    with ``re`` the particle Reynolds number on the superficial slip velocity
    alpha |u - v| d / nu_g (-), ``pr`` the gas Prandtl number (-), ``alpha`` the gas volume
    fraction around the particle (-). ``validity``: (low, high) of each of "re", "pr",
    "alpha" where the correlation rests on data; outside it is an extrapolation."""

    name: str
    nusselt: Callable
    validity: dict
    source: str


CORRELATIONS = Registry(__name__, __path__, "convection correlation")
"""{name: Correlation}; ``CORRELATIONS.lookup(name)`` for a message naming the choices."""
