"""The DEM contact law the engines use (LIGGGHTS' Hertz with damping), for the host and
for the comparison models of ``plugins.heat.comparison``."""
