"""Contact models registered by name: one module per model, file name = registry key.

A model pairs a compression law (``plugins.heat.compression``) with a recovery law
(``plugins.heat.recovery``); each module defines ``MODEL``.
"""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass


@dataclass(frozen=True)
class Model:
    """A contact model of Kosinski et al. (2014), sec. 5."""

    name: str
    compression: str          # key of plugins.heat.compression.COMPRESSION_LAWS
    recovery: str             # key of plugins.heat.recovery.RECOVERY_LAWS
    description: str


MODELS: dict[str, Model] = {
    info.name: importlib.import_module(f"{__name__}.{info.name}").MODEL
    for info in pkgutil.iter_modules(__path__)
}


def get_model(name: str) -> Model:
    """The model registered as ``name``; an unknown name raises ValueError with the choices."""
    try:
        return MODELS[name]
    except KeyError:
        raise ValueError(f"unknown contact model {name!r}; choices: {', '.join(sorted(MODELS))}") from None
