"""Registries by name, one API for every kind of model the plugins hold: heat models A, B, C
(``plugins.heat.models``), comparison heat models (``plugins.heat.comparison``), drag laws
(``plugins.drag``), Nusselt correlations (``plugins.convection.nusselt``) and lasting
conduction models (``plugins.conduction.contact``, ``plugins.conduction.gap``).

One module per entry in a package, file name = key, each defining ``MODEL``; modules whose
name starts with ``_`` are the package's helpers. A new model is one new file: the scene's
choices, ``collide``, ``post`` and the docs read the registry.
"""
from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Mapping


class Registry(Mapping):
    """{name: MODEL} of the modules of a package, read-only and in name order.

    ``registry[name]`` raises KeyError like a dict; ``registry.lookup(name)`` raises
    ValueError naming the kind of model and the choices, for messages to users."""

    def __init__(self, package: str, path, kind: str):
        self.kind = kind
        self._entries = {info.name: importlib.import_module(f"{package}.{info.name}").MODEL
                         for info in sorted(pkgutil.iter_modules(path), key=lambda i: i.name)
                         if not info.name.startswith("_")}

    def __getitem__(self, name):
        return self._entries[name]

    def __iter__(self):
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"Registry({self.kind}: {', '.join(self)})"

    def lookup(self, name: str):
        """The entry ``name``; ValueError naming the kind and the choices otherwise."""
        try:
            return self._entries[name]
        except KeyError:
            raise ValueError(f"unknown {self.kind} {name!r}; choices: {', '.join(self)}") from None
