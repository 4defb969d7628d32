"""Registries by name: one module per entry in a package, file name = key, each module
defining ``MODEL``."""
from __future__ import annotations

import importlib
import pkgutil


def collect(package: str, path) -> dict:
    """{module name: module.MODEL} for every module of ``package`` (its ``__path__``)."""
    return {info.name: importlib.import_module(f"{package}.{info.name}").MODEL for info in pkgutil.iter_modules(path)}


def lookup(registry: dict, name: str, kind: str):
    """registry[name]; an unknown name raises ValueError naming the ``kind`` and the choices."""
    try:
        return registry[name]
    except KeyError:
        raise ValueError(f"unknown {kind} {name!r}; choices: {', '.join(sorted(registry))}") from None
