"""What LIGGGHTS calls the things the host's messages and help name, for the user who writes
its scripts: the one place those names are written outside the bridge's own code (a second
engine's bridge would give its own). Imports nothing."""

CONDUCTION = "heat/gran"                 # the fix style that conducts heat through contacts
CONDUCTION_FIX = f"fix {CONDUCTION}"
MATERIAL_VALUES = "fix property/global"  # the script's per-type material values
WALL_FIX = "fix wall/gran"               # a granular wall: primitive or meshes
MESH_FIX = "fix mesh/surface"            # a mesh from an STL file
PAIR_CONTACTS = "pair/gran/local"        # the compute listing particle pairs in contact
WALL_CONTACTS = "wall/gran/local"        # the compute listing particle-wall contacts
TEMPERATURE = "f_Temp"                   # the particles' temperature as dumps name it
BOX = "create_box"                       # the command that makes the simulation box
COUPLING_FIX = "fix couple/cfd"          # CFDEM's coupling to the fluid
