"""The bridges to the engines: LIGGGHTS in process (``liggghts``, and ``dem``, which runs a
scene's script on it) and OpenFOAM's collheatFoam driven through named pipes (``openfoam``,
with ``fluid_case`` writing the box cases the host generates)."""
