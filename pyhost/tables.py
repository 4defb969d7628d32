"""What the host knows of the DEM's particles and walls before and beside LIGGGHTS: each atom
type's material (``TypeMaterials``), each particle's group and starting temperature
(``Known``), each wall's material and temperature (``HostWall``), and, for a box scene, that
no particle may leave (``LossWatch``). Built by ``pyhost.world`` (box_world, user_script) and
read by the effects through their ``pyhost.effects.Context``. SI units."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pyhost.failures import particles_lost
from pyhost.engines.liggghts.script import ScriptError


@dataclass(frozen=True)
class HostWall:
    """A LIGGGHTS wall as the host sees it: its fix id (and the index of the mesh within a
    mesh wall fix: each mesh is a wall of its own), its real material (index into the
    scene's materials) and its fixed temperature [K] (NaN: adiabatic)."""

    fix: str
    material: int
    temperature: float
    mesh: int = 0


def lookup(table: np.ndarray, keys) -> np.ndarray:
    """``table``'s entry for each of ``keys`` (ids or types), a key beyond the table taking its
    last entry (the tables of ``Known`` and ``TypeMaterials``, and their copies on the ranks)."""
    return table[np.minimum(keys, len(table) - 1)]


@dataclass(frozen=True)
class Known:
    """What the host knows of each particle before LIGGGHTS holds it, by atom id (a box scene:
    the host placed every particle) or by atom type (a user's script): the group of the
    history's T_group columns (index into ``names``; -1: none; a script's groups are its
    materials, a material with a temperature per type one group per type) and the starting
    temperature [K] (NaN: keep the value LIGGGHTS holds). Tables are indexed by the key; a key
    beyond a table takes its last entry."""

    by: str                 # "id" or "type"
    group: np.ndarray
    T: np.ndarray
    names: tuple

    def of(self, table: np.ndarray, atoms, mask=slice(None)) -> np.ndarray:
        """``table``'s entry (``group`` or ``T``) for each atom (of ``mask``)."""
        return lookup(table, getattr(atoms, self.by)[mask])


class TypeMaterials:
    """The material index of each atom type (``table``, index = type; -1: none) of the scene
    at ``where`` (its path, for the message of a type without one)."""

    def __init__(self, table, where):
        self.table = np.asarray(table, int)
        self.where = where

    def of(self, types) -> np.ndarray:
        """Material index of each of ``types``; ScriptError naming the types that have none."""
        table = self.table
        types = np.asarray(types)
        mat = np.where(types < len(table), lookup(table, types), -1)
        if (mat < 0).any():
            bad = sorted(set(types[mat < 0].tolist()))
            raise ScriptError(f"{self.where}: atom type(s) {bad} have no material: name them in a "
                              "[materials.NAME] types = [...] list")
        return mat


class LossWatch:
    """A box scene keeps every particle it placed: before each DEM chunk each rank keeps a copy
    of its particles (``Dem.keep_snapshot``, once per step), after it a lost one is a failure
    (``ParticlesLost``, exit 3) whose report says where it was last seen."""

    def __init__(self, scene, dem, known: Known):
        self.scene, self.dem, self.group = scene, dem, known.group
        self.before = None               # (time [s], step, particles) before the chunk under way

    def before_chunk(self, t: float) -> None:
        if self.before is None or self.before[1] != self.dem.step:
            self.before = (t, self.dem.step, self.dem.keep_snapshot())

    def after_chunk(self, t_now: float) -> None:
        if self.dem.count() < self.before[2]:
            ids, x, v = self.dem.snapshot()
            gone = np.setdiff1d(ids, self.dem.atoms(False).id)
            raise particles_lost(self.scene, gone, (self.before[0], ids, x, v), t_now, self.group)
