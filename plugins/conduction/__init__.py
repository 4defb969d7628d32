"""Lasting conduction between particles: through the solid contact of two touching particles
(``contact/``, one model per file) and through the gas gap between two particles near each
other (``gap/``, one model per file), and the heat a pair exchanges over an interval
(``exchange``). Pure, vectorised functions over arrays of pairs; SI units.

- ``CONTACT``, ``GAP``: the models by name (``plugins.registry.Registry``): the values of a
  scene's ``[effects] contact_conduction`` and ``gap_conduction``;
- ``Pair``: the pairs a model takes (radii, centre distance, conductivities, moduli);
- ``Gas``: the gas and the cut-offs a gap model takes;
- ``exchange``: see ``plugins.conduction.exchange``.

A contact model gives the conductance H [W/K] of the solid contact, zero for pairs apart; a
gap model that of the gas between them, zero beyond its cut-off. Heat flows into particle i
at H (T_j - T_i) [W].
"""
from __future__ import annotations

from plugins.conduction.contact import CONTACT, ContactModel
from plugins.conduction.exchange import exchange
from plugins.conduction.gap import GAP, GapModel
from plugins.conduction.pair import Gas, Pair

__all__ = ["CONTACT", "GAP", "ContactModel", "GapModel", "Gas", "Pair", "exchange"]
