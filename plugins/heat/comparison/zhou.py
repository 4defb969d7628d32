"""``zhou``: Kratos' thermal DEM direct conduction (Batchelor & O'Brien, simple form) with
Zhou et al.'s real-contact correction of the contact radius, integrated over the DEM's own
overlap history like ``softened``.

Source (KratosMultiphysics/Kratos, applications/ThermalDEMApplication):
- custom_constitutive/conduction/direct_conduction_bob_simple.cpp,
  ``DirectConductionBOBSimple::ComputeHeatFlux``: flux = 4 k_eff R_c dT, with
  k_eff = k1 k2 / (k1 + k2) (custom_elements/thermal_spheric_particle.cpp,
  ``ComputeEffectiveConductivity``);
- custom_elements/thermal_spheric_particle.cpp, ``ComputeContactRadius``: R_c is the radius
  of the circle where the overlapping spheres cut (against a wall, (R^2 - d^2)^(1/2)), the
  circle of heat/gran's area: pi R_c^2 = A of ``plugins.heat.comparison.softened``;
- custom_constitutive/real_contact/real_contact_zhou.cpp, ``RealContactZhou::AdjustContact``:
  R_c,adjusted = R_c (E*_sim / E*_real)^(1/5), E*_real with the real Young's moduli and the
  simulation's Poisson ratios (``ComputeEffectiveYoungReal``; Kratos scales both moduli by
  one ratio, here each material has its own real modulus).
So Q = softened's heat x (E*_sim/E*_real)^(1/5) / pi^(1/2), exactly, collision by collision.
e is NaN (no feedback).
"""
from __future__ import annotations

import math

from plugins.heat.comparison import ComparisonModel
from plugins.heat.comparison.softened import heat_gran


def heat(v0, pair, dem) -> dict:
    out = heat_gran(v0, pair, dem, area_correction=False)
    out["Q"] = out["Q"] * (dem.Ystar / dem.Ystar_original) ** 0.2 / math.sqrt(math.pi)
    return out


MODEL = ComparisonModel(
    name="zhou",
    description="Kratos thermal DEM: Batchelor-O'Brien 4 k R_c with Zhou's real-contact radius, over the DEM overlap",
    needs_dem=True,
    heat=heat,
)
