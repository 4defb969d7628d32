"""``softened_corrected``: as ``softened``, with heat/gran's ``area_correction yes``: the
overlap scaled by (Y*_DEM / Y*_original)^(2/3) before the contact area is formed
(CFDEMproject/LIGGGHTS-PUBLIC, src/fix_heat_gran_conduction.cpp, ``FixHeatGranCond::init``
and ``post_force_eval``). See ``plugins.heat.comparison.softened``."""
from plugins.heat.comparison import ComparisonModel
from plugins.heat.comparison.softened import heat_gran

MODEL = ComparisonModel(
    name="softened_corrected",
    description="LIGGGHTS fix heat/gran with area_correction yes over the DEM's softened overlap",
    needs_dem=True,
    heat=lambda v0, pair, dem: heat_gran(v0, pair, dem, area_correction=True),
)
