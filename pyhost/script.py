"""A user's LIGGGHTS input script, read as LIGGGHTS reads it, so the host can run it command
by command and turn each ``run N`` into N coupled steps.

``read_script(path)`` gives the commands with their file and line: '#' comments dropped
(outside quotes), '&' continuation lines joined, ``include FILE`` expanded in place (paths
relative to the case folder, where the script runs). Commands that need LIGGGHTS' own
input loop (``jump``, ``label``, ``next``) cannot be run one by one and are refused with
their line. ``$`` variables are left to LIGGGHTS, which substitutes them when each command
runs. The ``parse_*`` helpers read what the host must know about a command: the granular
walls (geometry of a primitive wall, meshes of a mesh wall), contact computes, heat/gran.
"""
from __future__ import annotations

import shlex
from dataclasses import dataclass, field
from pathlib import Path

from pyhost.walls import PRIMITIVES

REFUSED = {
    "jump": "loops and jumps need LIGGGHTS' own input loop",
    "label": "loops and jumps need LIGGGHTS' own input loop",
    "next": "loops and jumps need LIGGGHTS' own input loop",
    "quit": "the host ends the run itself",
    "shell": "the host does not run shell commands for a script",
}

HOST_PREFIX = "collheat_"
"""The ids of the fixes, computes and variables the host adds to a script (the contact
recorder ``collheat_events``, the fluid force ``collheat_fluid``, variables it evaluates): a
script's own may not begin so."""

HOST_ID_COMMANDS = ("fix", "unfix", "fix_modify", "compute", "uncompute", "compute_modify", "variable")
"""Commands whose second word is the id of a fix, compute or variable."""


class ScriptError(ValueError):
    """A script the host cannot run, naming the file and the line."""


@dataclass(frozen=True)
class Command:
    text: str
    file: str
    line: int

    @property
    def words(self) -> list[str]:
        return shlex.split(self.text, posix=True) if self.text else []

    @property
    def name(self) -> str:
        return self.text.split(None, 1)[0]

    def where(self) -> str:
        return f"{self.file}:{self.line}"


def _strip_comment(line: str) -> str:
    quote = None
    for k, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            return line[:k]
    return line


def script_commands(path: str | Path, folder: str | Path | None = None, _depth: int = 0) -> list[Command]:
    """The commands of a LIGGGHTS script as LIGGGHTS reads them: '#' comments (outside quotes)
    dropped, '&' continuations joined, included files read in their place; each with its file
    and first line. ``folder``: where relative include paths are found (default the script's
    own folder). ScriptError for a file that is missing or not text, an include nested more
    than 20 deep or of a variable file name, or a script ending inside a continuation."""
    path = Path(path)
    folder = Path(folder) if folder is not None else path.parent
    if _depth > 20:
        raise ScriptError(f"{path}: include nested more than 20 deep")
    try:
        raw = path.read_text().splitlines()
    except FileNotFoundError:
        raise ScriptError(f"{path}: no such LIGGGHTS script") from None
    except UnicodeDecodeError as exc:
        raise ScriptError(f"{path}: not a text file ({exc.reason} at byte {exc.start})") from None
    commands, pending, first = [], "", 0
    for number, line in enumerate(raw, start=1):
        text = _strip_comment(line).rstrip()
        if not pending:
            first = number
        if text.endswith("&"):
            pending += text[:-1] + " "
            continue
        text = (pending + text).strip()
        pending = ""
        if not text:
            continue
        cmd = Command(" ".join(text.split()) if '"' not in text and "'" not in text else text, str(path), first)
        if cmd.name == "include":
            words = cmd.words
            if len(words) != 2:
                raise ScriptError(f"{cmd.where()}: include takes one file name")
            if "$" in words[1]:
                raise ScriptError(f"{cmd.where()}: include of a variable file name is not supported")
            commands += script_commands(folder / words[1], folder, _depth + 1)
            continue
        commands.append(cmd)
    if pending:
        raise ScriptError(f"{path}:{first}: the script ends inside a '&' continuation")
    return commands


def read_script(path: str | Path, folder: str | Path | None = None, temperatures: bool = True) -> list[Command]:
    """The commands of a LIGGGHTS script the host runs (``script_commands``), with what the
    host cannot run refused before any engine time (see the module doc), and what would
    remove or replace a fix the host adds (``_check_host_ids``; ``temperatures``: whether
    the host adds the Temp property at the first run, where the script has none)."""
    commands = script_commands(path, folder)
    _check_host_ids(commands, temperatures)
    for cmd in commands:
        if cmd.name in REFUSED:
            raise ScriptError(f"{cmd.where()}: '{cmd.name}': {REFUSED[cmd.name]}; the host runs a script "
                              "command by command (unroll the loop, or give the values as variables)")
        if cmd.name == "if":
            _check_if(cmd)
        if cmd.name == "delete_atoms":
            _check_delete(cmd)
        if cmd.name == "units" and cmd.text.split()[1:] != ["si"]:
            raise ScriptError(f"{cmd.where()}: '{cmd.text}': the host's contact models, heat and energy balance "
                              "are in SI; give 'units si' (and the script's values in SI)")
        style = cmd.text.split()[3] if cmd.name == "fix" and len(cmd.text.split()) > 3 else ""
        if style.split("/")[-1] == "multisphere":
            raise ScriptError(f"{cmd.where()}: fix {style}: rigid clumps of spheres (multisphere) are not "
                              "supported: the collision heat models and the energy balance take each atom for a "
                              "sphere of its own mass, and a clump's spheres carry the whole clump's")
        if cmd.name == "run":
            parse_run(cmd)              # 'run ... every' and other forms refused before any engine time
    return commands


def host_fix_refusal(line: str) -> str | None:
    """Why a LIGGGHTS command would remove or replace a fix, compute or variable of the host's
    (its id begins with HOST_PREFIX, or it unfixes Temp), or None."""
    w = line.split()
    if len(w) < 2 or w[0] not in HOST_ID_COMMANDS:
        return None
    if w[1].startswith(HOST_PREFIX):
        return (f"'{line}': ids beginning with '{HOST_PREFIX}' are the host's own (its contact recorder fix "
                "collheat_events, its fluid force fix collheat_fluid, the variables it evaluates): the script may "
                "not define, remove or change one (without the recorder no collision is seen); give the script's "
                "own another id")
    if w[:2] == ["unfix", "Temp"]:
        return ("'unfix Temp': the particles' temperatures live in the Temp property (the host's collision heat "
                "and energy balance read and write it): the script may not remove it")
    return None


def _check_host_ids(commands: list[Command], temperatures: bool) -> None:
    """A script's command that would remove or replace what the host adds (Dem.prepare, at
    the first run) is refused with its file and line: without the contact recorder no
    collision is seen and no heat moves, and the run would still end as done. Refused: a
    fix, compute or variable (its definition, unfix, uncompute, modify) whose id begins with
    HOST_PREFIX, inside an 'if' too; 'unfix Temp' (the particles' temperatures live in that
    property, the host's or heat/gran's); and a 'fix Temp' after the first run when the host
    added that property there (no fix Temp or heat/gran before it)."""
    first_run = next((k for k, c in enumerate(commands) if c.name == "run"), len(commands))
    own_temp = any(c.name == "fix" and (c.text.split()[1:2] == ["Temp"] or c.text.split()[3:4] == ["heat/gran"]
                                        or c.text.split()[3:5] == ["property/atom", "Temp"])
                   for c in commands[:first_run])      # (as Dem.prepare decides)
    for k, cmd in enumerate(commands):
        for line in _if_commands(cmd) if cmd.name == "if" else [cmd.text]:
            w = line.split()
            why = host_fix_refusal(line)
            if why:
                raise ScriptError(f"{cmd.where()}: {why}")
            if w[:2] == ["fix", "Temp"] and k > first_run and temperatures and not own_temp:
                raise ScriptError(f"{cmd.where()}: '{line}': the host adds 'fix Temp all property/atom Temp' at "
                                  f"the script's first run ({commands[first_run].where()}), where the script has "
                                  "none: this would replace it and the temperatures it holds; define the script's "
                                  "fix Temp before its first run")


def check_types(commands: list[Command], materials: dict, where: str) -> None:
    """Types the scene gives its materials must exist: a type above the script's
    ``create_box N`` would end LIGGGHTS' process (an out-of-bounds index in a property/global)
    at the first run; ScriptError naming the material, the type and the create_box line,
    before any engine time. A script that reads its box (read_restart, read_data) is checked
    by LIGGGHTS itself."""
    box = next((c for c in commands if c.name == "create_box"), None)
    if box is None:
        return
    try:
        n = int(box.words[1])
    except (IndexError, ValueError):
        return                                  # a $variable: LIGGGHTS resolves it
    for name, m in materials.items():
        for t in m.types:
            if t > n:
                raise ScriptError(f"{where}: materials.{name}.types: atom type {t} does not exist: "
                                  f"{box.where()} creates {n} atom type{'s' if n > 1 else ''}")


def _check_delete(cmd: Command) -> None:
    """``delete_atoms`` renumbers the atoms left (LIGGGHTS' default ``compress yes`` gives them
    the ids 1..N again), and the host follows each particle by its id: its heat content in
    the balance, the collision log, a checkpoint. A particle would take over another's id,
    the heat that left with the deleted ones would be counted as set by the script."""
    try:
        words = cmd.words
    except ValueError:
        return                          # unbalanced quotes: LIGGGHTS says so itself
    k = words.index("compress") + 1 if "compress" in words else len(words)
    if words[k:k + 1] == ["no"]:
        return
    raise ScriptError(f"{cmd.where()}: 'delete_atoms' renumbers the remaining atoms' ids (LIGGGHTS' default "
                      "'compress yes'), and the host follows each particle by its id (its heat content, the "
                      "collision log): add 'compress no' to the command")


def _if_commands(cmd: Command) -> list[str]:
    """The commands inside ``if ... then "..." [elif ... "..."] [else "..."]`` (and elif's
    conditions, which name no command); none for unbalanced quotes (LIGGGHTS says so itself)."""
    try:
        words = cmd.words
    except ValueError:
        return []
    return [w for w in words[2:] if w not in ("then", "elif", "else") and w.strip()]


def _check_if(cmd: Command) -> None:
    """The commands inside an ``if`` run inside LIGGGHTS, where the host cannot couple them:
    a ``run`` there would be uncoupled steps whose collisions are never seen, and a refused
    command would slip through."""
    for name in (line.split(None, 1)[0] for line in _if_commands(cmd)):
        if name == "run" or name in REFUSED:
            why = ("the host couples every run itself: write the run outside the if (give its steps as a variable)"
                   if name == "run" else REFUSED[name])
            raise ScriptError(f"{cmd.where()}: '{name}' inside 'if': {why}")


BOX = ("create_box", "read_data", "read_restart")
STATE = {"create_atoms", "delete_atoms", "displace_atoms", "set", "velocity", "read_dump", "change_box",
         "reset_timestep", "group", "write_restart", "write_data", "write_dump", "print", *BOX}
"""Commands whose effect is in LIGGGHTS' restart file (atoms and their values, groups, the box,
the step) or that only wrote output: a restart does not replay them."""


def replay(commands: list[Command], upto: int, restart: Path) -> list[Command]:
    """The set-up of a script restarted at its command number ``upto`` (a ``run`` that a
    checkpoint interrupted): commands[:upto] with the first box command (create_box, read_data,
    read_restart) replaced by ``read_restart`` of the checkpoint's file, what the file holds
    (``STATE``) left out, and the rest (regions, variables, fixes and unfixes under their ids,
    which take their state back from the file, computes, pair style, dumps) replayed in order;
    a dump or log to one file appends to it. Earlier runs stay in the list as markers (the
    host adds its own fixes at the first, as in the run that wrote the checkpoint); they
    simulate nothing. ScriptError for a command whose effect the host cannot know (an ``if``)."""
    out, box = [], False
    for cmd in commands[:upto]:
        name = cmd.name
        if name == "if":
            raise ScriptError(f"--restart: {cmd.where()}: an 'if' before the interrupted run; the host cannot "
                              "tell what it did, so it cannot restart this script (move it after the last run, "
                              "or give the values as variables)")
        if name in BOX and not box:
            box = True
            out.append(Command(f"read_restart {restart}", cmd.file, cmd.line))
            continue
        if name in STATE:
            continue
        out.append(cmd)
        words = cmd.words
        if name == "dump" and len(words) >= 6 and "*" not in words[5] and "%" not in words[5]:
            out.append(Command(f"dump_modify {words[1]} append yes", cmd.file, cmd.line))
        if name == "log" and len(words) == 2:
            out[-1] = Command(f"log {words[1]} append", cmd.file, cmd.line)
    if not box:
        raise ScriptError(f"--restart: the script defines no box (create_box, read_data or read_restart) before "
                          f"{commands[upto].where()}")
    return out


RANDOMS = {"insert": ("insert",), "particledistribution/discrete": ("distribution",),
           "particletemplate/sphere": ("template_insertion", "template_mc")}
"""Fix styles (insert/* as "insert") whose random generators a restart puts back, by the kind
``Liggghts.random_state`` knows them as."""


@dataclass(frozen=True)
class RunCommand:
    """``run N [upto] [pre yes|no] [post yes|no]``: steps (possibly a $variable, evaluated by
    the host through LIGGGHTS) and whether N is an end step."""

    steps: str
    upto: bool


def parse_run(cmd: Command) -> RunCommand:
    words = cmd.words
    if len(words) < 2:
        raise ScriptError(f"{cmd.where()}: 'run' needs a number of steps")
    rest, upto = words[2:], False
    while rest:
        key = rest.pop(0)
        if key == "upto":
            upto = True
        elif key in ("pre", "post") and rest:
            rest.pop(0)
        elif key in ("start", "stop") and rest:
            rest.pop(0)
        else:
            raise ScriptError(f"{cmd.where()}: 'run ... {key}' is not supported by the host (supported: "
                              "run N [upto] [pre yes|no] [post yes|no])")
    return RunCommand(words[1], upto)


def output_files(cmd: Command) -> list[str]:
    """The files a command makes LIGGGHTS open without making their folder, as the script
    names them (relative to where the script runs; ``$`` variables unresolved): a fix's
    ``file`` or ``append`` keyword (fix print, ave/time, ...), restart's, write_data's and
    log's. (dump, write_dump and write_restart make theirs: LIGGGHTS' dump.cpp and
    write_restart.cpp.)"""
    w = cmd.words
    at = {"write_data": [1], "log": [1]}.get(w[0], [])
    if w[0] == "restart" and len(w) > 2 and w[1] != "0":
        at = [2, 3]
    if w[0] == "fix":
        at = [k + 1 for k in range(4, len(w)) if w[k] in ("file", "append")]
    return [w[k] for k in at if k < len(w)]


def _keyword(words: list[str], name: str) -> str | None:
    """The word after keyword ``name`` of a fix command (its 5th word on), or None."""
    at = [k for k in range(4, len(words) - 1) if words[k] == name]
    return words[at[-1] + 1] if at else None


def _contact_area(words: list[str]) -> tuple:
    """A fix wall/gran's ``contact_area`` (its heat conduction's): (mode, constant area as written)."""
    mode = _keyword(words, "contact_area") or "overlap"
    return (mode, _keyword(words, "constant") if mode == "constant" else None)


@dataclass(frozen=True)
class GranWall:
    """A ``fix ID group wall/gran ...``: a primitive wall (``primitive`` = (kind, numbers),
    kind xplane, yplane, zplane, xcylinder, ycylinder or zcylinder; numbers None where the
    script gives them as variables) or mesh walls (``meshes``: ids of their fix mesh/surface).
    ``temperature``: a primitive wall's ``temperature`` as written (a number or a $variable),
    with which the script's fix heat/gran conducts through its contacts; None: none.
    ``contact_area``: its ``contact_area`` for that conduction, ("overlap" | "projection" |
    "constant", the constant area as written or None)."""

    fix: str
    primitive: tuple | None = None
    meshes: tuple = ()
    type: int | None = None
    moving: bool = False
    temperature: str | None = None
    contact_area: tuple = ("overlap", None)


def parse_wall(cmd: Command) -> GranWall | None:
    """The wall of a ``fix ... wall/gran`` command, or None if the command is not one."""
    w = cmd.words
    if len(w) < 4 or w[0] != "fix" or w[3] != "wall/gran":
        return None
    if "primitive" in w:
        k = w.index("primitive")
        try:
            wall_type = int(w[w.index("type", k) + 1])
            kind = next(x for x in w[k:] if x in PRIMITIVES)
        except (ValueError, StopIteration, IndexError):
            raise ScriptError(f"{cmd.where()}: primitive wall the host cannot read (supported: "
                              f"{', '.join(PRIMITIVES)}, with a plain number after 'type')") from None
        # LIGGGHTS has the geometry and the contact recorder reads it from the fix: a position
        # given as a ${variable} is fine, the host keeps no numbers then
        at = w.index(kind, k)
        try:
            numbers = tuple(float(x) for x in w[at + 1: at + 1 + PRIMITIVES[kind]])
        except ValueError:
            numbers = None
        return GranWall(w[1], primitive=(kind, numbers), type=wall_type,
                        moving=any(x in w for x in ("wiggle", "shear", "rotate")), temperature=_keyword(w, "temperature"),
                        contact_area=_contact_area(w))
    if "meshes" in w:
        k = w.index("meshes")
        n = int(w[w.index("n_meshes") + 1]) if "n_meshes" in w else 1
        return GranWall(w[1], meshes=tuple(w[k + 1: k + 1 + n]), contact_area=_contact_area(w))
    raise ScriptError(f"{cmd.where()}: fix wall/gran with neither 'primitive' nor 'meshes'")


@dataclass
class ScriptInfo:
    """What the host learns from the commands run so far."""

    walls: dict = field(default_factory=dict)           # fix id -> GranWall
    mesh_types: dict = field(default_factory=dict)      # fix mesh/surface id -> atom type of the wall
    mesh_temperatures: dict = field(default_factory=dict)  # fix mesh/surface id -> its 'temperature' as written
    heat_gran: str | None = None                        # id of fix heat/gran
    temp_fix: bool = False                              # a fix property/atom Temp exists
    globals: dict = field(default_factory=dict)         # property/global name -> fix id
    periodic: tuple = (False, False, False)             # from the boundary command
    mesh_motions: list = field(default_factory=list)    # ids of the fix move/mesh defined now
    randoms: list = field(default_factory=list)         # "what id" of insertion's random generators

    def wall_type(self, fix: str, mesh: int = 0) -> int | None:
        """The LIGGGHTS atom type of a wall fix's primitive, or of its mesh number ``mesh``."""
        wall = self.walls.get(fix)
        if wall is None:
            return None
        return wall.type if wall.primitive is not None else self.mesh_types.get(wall.meshes[mesh])

    def conducting_temperature(self, fix: str, mesh: int = 0) -> str | None:
        """The temperature, as written (a number or a $variable: the engine evaluates it), at
        which the script's fix heat/gran conducts into the contacts of a wall fix's primitive,
        or of its mesh number ``mesh``; None: none (or no heat/gran)."""
        wall = self.walls.get(fix)
        if wall is None or self.heat_gran is None:
            return None
        return wall.temperature if wall.primitive is not None else self.mesh_temperatures.get(wall.meshes[mesh])

    def wall_temperatures(self, fix: str) -> list[str]:
        """The temperatures a wall fix's primitive, or its meshes, have in the script (as
        written), with which a fix heat/gran conducts through their contacts."""
        wall = self.walls.get(fix)
        if wall is None:
            return []
        found = [wall.temperature] if wall.primitive is not None else [self.mesh_temperatures.get(m) for m in wall.meshes]
        return [t for t in found if t is not None]

    def _random(self, key: str, defined: bool) -> None:
        if key in self.randoms:
            self.randoms.remove(key)
        if defined:
            self.randoms.append(key)

    def learn(self, cmd: Command) -> None:
        w = cmd.words
        if w[0] == "fix" and len(w) >= 4:
            style = w[3]
            if style == "wall/gran":
                self.walls[w[1]] = parse_wall(cmd)
            elif style.startswith("mesh/surface") and "type" in w:
                self.mesh_types[w[1]] = int(w[w.index("type") + 1])
                if _keyword(w, "temperature") is not None:
                    self.mesh_temperatures[w[1]] = _keyword(w, "temperature")
            elif style == "heat/gran":
                self.heat_gran = w[1]
            elif style == "property/atom" and len(w) >= 5 and w[4] == "Temp":
                self.temp_fix = True
            elif style == "property/global" and len(w) >= 5:
                self.globals[w[4]] = w[1]
            elif style.startswith("move/mesh") and w[1] not in self.mesh_motions:
                self.mesh_motions.append(w[1])
            for what in RANDOMS.get(style.split("/")[0] if style.startswith("insert/") else style, ()):
                self._random(f"{what} {w[1]}", True)
        elif w[0] == "unfix" and len(w) == 2:
            self.walls.pop(w[1], None)
            if w[1] in self.mesh_motions:
                self.mesh_motions.remove(w[1])
            self.randoms = [k for k in self.randoms if k.split(" ", 1)[1] != w[1] or k.startswith("region ")]
            if self.heat_gran == w[1]:
                self.heat_gran = None
        elif w[0] == "region" and len(w) >= 3:
            self._random("region " + w[1], w[2] != "delete")
        elif w[0] == "boundary" and len(w) >= 4:
            self.periodic = tuple(b == "p" for b in w[1:4])
