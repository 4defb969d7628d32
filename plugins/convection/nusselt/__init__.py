"""Nusselt correlations registered by name: one module per correlation, file name = registry
key = the value of ``[effects] convection``. Each module defines ``CORRELATION``."""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from typing import Callable


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


CORRELATIONS: dict[str, Correlation] = {
    info.name: importlib.import_module(f"{__name__}.{info.name}").CORRELATION
    for info in pkgutil.iter_modules(__path__)
}
