"""Contact models registered by name: one module per model, file name = registry key.

A model pairs a compression law (``plugins.heat.compression``) with a recovery law
(``plugins.heat.recovery``); each module defines ``MODEL``.
"""
from __future__ import annotations

from dataclasses import dataclass

from plugins.registry import Registry


@dataclass(frozen=True)
class Model:
    """A contact model of Kosinski et al. (2014), sec. 5."""

    name: str
    compression: str          # key of plugins.heat.compression.COMPRESSION_LAWS
    recovery: str             # key of plugins.heat.recovery.RECOVERY_LAWS
    description: str


MODELS = Registry(__name__, __path__, "contact model")
"""{name: Model}; ``MODELS.lookup(name)`` for a message naming the choices."""
