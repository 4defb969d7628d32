"""Contact conduction models registered by name: one module per model, file name = registry
key = the value of ``[effects] contact_conduction``. Each module defines ``MODEL``, a
``ContactModel``."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from plugins.registry import Registry


@dataclass(frozen=True)
class ContactModel:
    """Conduction through the solid contact of two touching spheres: ``conductance(pair)`` ->
    H [W/K] per pair (``plugins.conduction.Pair``), 0 where the two do not overlap; heat into
    i at H (T_j - T_i). ``source``: the paper and the code it follows."""

    name: str
    conductance: Callable
    source: str


CONTACT = Registry(__name__, __path__, "contact conduction model")
"""{name: ContactModel}; ``CONTACT.lookup(name)`` for a message naming the choices."""
