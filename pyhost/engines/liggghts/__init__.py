"""The LIGGGHTS 3.8 bridge: what knows LIGGGHTS' syntax, with ``pyhost.engines.dem`` (a scene's
script run on it, behind ``pyhost.engines.interface``) and ``pyhost.engines.events`` (its
contact recorder).

- ``library``: LIGGGHTS in process through ctypes (``Liggghts``), its errors;
- ``script``: a user's input script read as LIGGGHTS reads it, its grammar (``Command``,
  ``parse_run``, ``parse_wall``), its replay at a restart and what the host learns from the
  commands run (``ScriptInfo``): the one interpreter of scripts, which runs and post use;
- ``box_input``: the input of a box scene's generated world (data file, commands);
- ``worlds``: how the host sees a box world's or a user's script's particles and walls;
- ``computes``: the local computes' columns (``dump local`` of pair/gran/local, wall/gran/local);
- ``dump_script``: the script that wrote a run's dumps, as post reads it (through ``script``);
- ``dump_contacts``: collisions from the contact dumps of those computes, for post;
- ``names``: what LIGGGHTS calls the commands the host's messages name.
"""
from pyhost.engines.liggghts.library import Liggghts, LiggghtsError, LiggghtsFailed, granular_box  # noqa: F401
