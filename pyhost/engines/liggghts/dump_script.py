"""The LIGGGHTS input that wrote a run's dumps, as post reads it (``read_script``): its time step
and runs (a ``Clock``), local computes, walls, property/globals and Temp sets, each learnt by
the script interpreter the runs use (``pyhost.engines.liggghts.script``: ``script_commands``,
``ScriptInfo.learn``); ``$`` variables substituted by LIGGGHTS itself running the script's
set-up in a process of its own (``resolve_setup``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from pyhost.dumps import Clock, _is_number
from pyhost.engines.liggghts.box_input import script_dem_contacts
from pyhost.engines.liggghts.computes import LOCAL_STYLES, parse_compute
from pyhost.engines.liggghts.script import (Command, ScriptError, ScriptInfo, script_commands, sets_temperature,
                                            step_after)
from pyhost.walls import PRIMITIVES


@dataclass(frozen=True)
class Script:
    """What post-processing needs from the LIGGGHTS input that wrote the dumps."""

    timestep: float | None
    computes: dict                  # id -> Compute (local styles only)
    mesh_wall_fixes: tuple          # ids of wall/gran fixes with meshes, in script order
    warnings: tuple = ()
    box: np.ndarray | None = None   # (3, 2) lo hi [m] of its create_box, None if unknown
    heat_gran: tuple = ()           # ids of its fix heat/gran
    primitives: dict = field(default_factory=dict)  # primitive wall fix id -> (kind, numbers) (pyhost.walls)
    globals: dict = field(default_factory=dict)     # property/global name -> (where, words after the name)
    wall_types: dict = field(default_factory=dict)  # wall/gran fix id -> atom type of its primitive or first mesh
    temperature_sets: tuple = ()    # (count or None if unknown, where, command) of each 'set ... property/atom Temp'
    clock: Clock | None = None      # its runs' steps and times (None: a run's steps or its first step unknown)


SETUP_COMMANDS = ("units", "dimension", "boundary", "atom_style", "atom_modify", "newton", "communicate",
                  "lattice", "variable", "region", "create_box", "timestep")
"""What post asks LIGGGHTS to run of a script to learn its time step and box as LIGGGHTS
resolves them (variables, ${...}): set-up only, no particles, no runs, no files written."""


SAME_IN_SETUP = frozenset("sqrt exp ln log abs sin cos tan asin acos atan atan2 ceil floor round ternary PI "
                          "xlo xhi ylo yhi zlo zhi lx ly lz vol".split())
"""What an equal-style formula may name, besides numbers and other such variables, and mean in
post's set-up (a box, no particles, no step run) what it means in the run."""

_NUMBER = re.compile(r"(?<![A-Za-z_])(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_REFERENCE = re.compile(r"\$\{(\w+)\}|\$(\w)|\bv_(\w+)")


def _references(text: str) -> set[str]:
    """The variables a command or formula names: ${name}, $x and v_name."""
    return {a or b or c for a, b, c in _REFERENCE.findall(text)}


def _read_by_post(words: list[str]) -> bool:
    """Whether post reads this command's values, whose ``$`` variables it then has LIGGGHTS
    substitute at their place in the set-up: a fix property/global, a primitive wall, a run
    or reset_timestep, a timestep, a set of Temp."""
    return (words[0] in ("run", "reset_timestep", "timestep")
            or words[0] == "fix" and len(words) > 3 and (words[3] == "property/global"
                                                         or words[3] == "wall/gran" and "primitive" in words)
            or words[0] == "set" and "property/atom" in words and "Temp" in words)


def setup_variables(lines: list[tuple[int, str]], given: dict) -> tuple[set[str], dict[str, str]]:
    """Which variables of a script's ``variable`` commands (and ``given``, the command line's
    ``-var``) post's set-up gives the run's values: (those names, why each other one cannot:
    an atom-style, file or python variable, or an equal-style formula naming what needs the
    particles or the run, such as count(all), step or c_ID). A name defined more than once
    must be so in each definition."""
    why, depends = {}, {}
    for _, text in lines:
        words = text.split()
        if words[0] != "variable" or len(words) < 3 or words[2] == "delete":
            continue
        name, style, rest = words[1], words[2], " ".join(words[3:])
        depends.setdefault(name, set())
        if style in ("index", "string", "universe", "uloop", "loop", "world", "format"):
            depends[name] |= _references(rest) | ({words[3]} if style == "format" and len(words) > 3 else set())
        elif style == "equal":
            formula = _NUMBER.sub(" ", _REFERENCE.sub(" ", rest.strip("\"'")))
            other = sorted(set(re.findall(r"[A-Za-z_]\w*", formula)) - SAME_IN_SETUP)
            if other:
                why.setdefault(name, f"its formula names {', '.join(other)}")
            depends[name] |= _references(rest)
        else:
            why.setdefault(name, f"it is {style}-style")
    known = set(depends) | set(given)
    changed = True
    while changed:                      # what depends on a variable post cannot evaluate cannot either
        changed = False
        for name, needs in depends.items():
            bad = next((n for n in sorted(needs) if n in why or n not in known), None)
            if bad is not None and name not in why:
                why[name] = f"it names {bad}" + ("" if bad in known else " (not defined)")
                changed = True
    return {n for n in known if n not in why}, why


def resolve_setup(lines: list[tuple[int, str]], path: Path, asked: list[tuple[int, str]] = (),
                  variables: dict | None = None) -> tuple[float | None, np.ndarray | None, dict, str | None]:
    """Time step [s] and box (3, 2) [m] of a script's set-up commands ``lines`` (line
    number, text) as LIGGGHTS itself evaluates them, and the commands ``asked`` with their
    variables substituted at their place ({line number: text}): the ``liggghts`` program runs
    the set-up in a scratch folder, with ``variables`` as its ``-var`` options, and prints the
    values (a process of its own: its VTK and pyvista's do not share one). (None, None, {},
    why) when LIGGGHTS refuses one of them."""
    import subprocess
    import tempfile

    timestep = [t.split(None, 1)[1] for _, t in lines if t.split()[0] == "timestep"]
    boxed = any(t.split()[0] == "create_box" for _, t in lines)
    prints = [(n, f'print "COLLHEAT_LINE {n} {t}"') for n, t in asked]
    body = [t for _, t in sorted([*lines, *prints], key=lambda nt: nt[0]) if t.split()[0] != "timestep"]
    if timestep:
        body.append(f'print "COLLHEAT_DT {timestep[-1]}"')
    if boxed:
        names = [f"{a}{e}" for a in "xyz" for e in ("lo", "hi")]
        body += [f"variable collheat_{n} equal {n}" for n in names]
        body.append('print "COLLHEAT_BOX ' + " ".join(f"${{collheat_{n}}}" for n in names) + '"')
    given = [w for name, value in (variables or {}).items() for w in ("-var", name, str(value))]
    with tempfile.TemporaryDirectory(prefix="collheat-setup-") as tmp:
        (Path(tmp) / "in.setup").write_text("\n".join(body) + "\n")
        # line-buffered: LIGGGHTS' error line would be lost in the buffer at its MPI_Abort
        r = subprocess.run(["stdbuf", "-oL", "liggghts", "-in", "in.setup", "-log", "none", *given],
                           cwd=tmp, capture_output=True, text=True, errors="replace", timeout=120)
    screen = r.stdout
    errors = [ln for ln in screen.splitlines() if ln.startswith("ERROR")]
    if r.returncode or errors:
        return None, None, {}, f"{path}: {(errors or ['no message, exit ' + str(r.returncode)])[-1]}"
    values = {ln.split()[0]: ln.split()[1:] for ln in screen.splitlines() if ln.startswith("COLLHEAT_")}
    dt = float(values["COLLHEAT_DT"][0]) if "COLLHEAT_DT" in values else None
    box = np.array(values["COLLHEAT_BOX"], float).reshape(3, 2) if "COLLHEAT_BOX" in values else None
    substituted = {int(ln.split()[1]): ln.split(None, 2)[2] for ln in screen.splitlines()
                   if ln.startswith("COLLHEAT_LINE ")}
    return dt, box, substituted, None


def check_given_numbers(commands, setup, where_of, given: dict) -> None:
    """A ``--var NAME VALUE`` whose value is not a number, where a command post reads as numbers
    (a timestep, run, property/global, primitive wall, Temp set) takes it, directly or through
    the script's variables: ValueError naming the variable, its value and the command's line.
    (LIGGGHTS would put the word in the command; post could not read the value and used the
    scene's instead, with exit 0.)"""
    bad = {name: value for name, value in given.items() if not _is_number([value])}
    if not bad:
        return
    needs = {}                          # a set-up variable -> the variables its definition names
    for _, text in setup:
        words = text.split()
        if words[0] == "variable" and len(words) > 3:
            needs.setdefault(words[1], set()).update(_references(" ".join(words[3:])))
    for number, line in commands:
        if "$" not in line or not _read_by_post(line.split()):
            continue
        seen, todo = set(), list(_references(line))
        while todo:                     # the variables it names, and those they name in turn
            name = todo.pop()
            if name not in seen:
                seen.add(name)
                todo.extend(needs.get(name, ()) if name not in given else ())
        name = next((n for n in sorted(seen) if n in bad), None)
        if name is not None:
            raise ValueError(f"--var {name} {bad[name]!r}: not a number, and {where_of[number]} takes it as one "
                             f"('{line}')")


def read_script(path, variables: dict | None = None) -> Script:
    """Reads ``timestep``, the local computes and the mesh wall fixes of a LIGGGHTS input, its
    property/globals, wall types, and the steps at which it sets particles' Temp (counted
    through its ``run N [upto]`` and ``reset_timestep``), read as the run reads it
    (``pyhost.engines.liggghts.script.script_commands``: ``&`` continuations, ``#`` comments, included files
    in their place, relative to the script's folder). ``$`` variables in those commands are
    substituted by LIGGGHTS at their place in the script's set-up (``resolve_setup``), with
    ``variables`` as LIGGGHTS' command line ``-var`` gives them, where post's set-up gives them
    the run's values (``setup_variables``); a command whose variables it cannot substitute keeps
    them, and a warning says why."""
    path = Path(path)
    read = script_commands(path)
    commands = list(enumerate(c.text for c in read))        # (place in the script, text)
    where_of = [f"{c.file}: line {c.line}" for c in read]
    variables = {str(k): str(v) for k, v in (variables or {}).items()}
    setup = [(number, line) for number, line in commands if line.split()[0] in SETUP_COMMANDS]
    same, why_not = setup_variables(setup, variables)
    check_given_numbers(commands, setup, where_of, variables)
    warnings, asked = [], []
    for number, line in commands:
        if "$" not in line or not _read_by_post(line.split()):
            continue
        bad = sorted(_references(line) - same)
        reasons = [f"{n}: {why_not.get(n, 'not defined (give --var ' + n + ' VALUE)')}" for n in bad]
        if '"' in line or "$(" in line:
            reasons.append("a quoted text or an immediate $(...)")
        if reasons:
            warnings.append(f"{where_of[number]}: post cannot substitute its variables ({'; '.join(reasons)})")
        else:
            asked.append((number, line))
    literal = all(_is_number(line.split()[1:2]) for _, line in setup if line.split()[0] == "timestep")
    substituted, dt, box = {}, None, None
    if asked or not literal or any(line.split()[0] == "create_box" for _, line in setup):
        dt, box, substituted, why = resolve_setup(setup, path, asked, variables)
        if why and asked:               # the set-up alone, as without the substitutions
            dt, box, substituted, why_setup = resolve_setup(setup, path, (), variables)
            if not why_setup:
                warnings.append(f"LIGGGHTS could not substitute the script's variables ({why}): they stay unread")
            why = why_setup
        if why:
            undefined = sorted({n for _, line in setup for n in _references(line)} - same - set(why_not))
            warnings.append(f"LIGGGHTS could not run the script's set-up ({why}"
                            + (f"; not defined: {', '.join(undefined)}: give --var NAME VALUE as on LIGGGHTS' "
                               "command line" if undefined else "")
                            + "): its time step, box and variables are unknown; give --dt")
    info = ScriptInfo()          # the script's commands read as a run reads them, with their substitutions
    timestep, step, temperature_sets, ran = None, 0, [], False   # the step reached (None: unknown); any run yet
    runs, count, t = [], 0, 0.0     # the clock's runs so far, the steps counted through them, the time [s]
    for number, line in commands:
        cmd = Command(substituted.get(number, line), read[number].file, read[number].line)
        try:
            info.learn(cmd)
        except (ScriptError, ValueError):
            pass                        # a wall the run would refuse: post places none
        if cmd.name == "timestep" and info.timestep is not None:
            timestep = float(info.timestep) if _is_number([info.timestep]) else dt
        first, step = step, step_after(cmd, step)
        if cmd.name == "run" and runs is not None:
            if first is None or step is None or timestep is None:
                runs = None             # (a read_restart's step, a run of $variable steps: no clock)
            elif step > first:
                runs.append((first, step, timestep, t))
                count, t = count + step - first, t + (step - first) * timestep
        ran = ran or cmd.name == "run"
        if ran and sets_temperature(cmd):    # (before any run: the first frame's)
            temperature_sets.append(((count, step), where_of[number], " ".join(cmd.text.split())))
    where = lambda c: f"{c.file}: line {c.line}"
    computes = {}
    for c in info.computes.values():
        if len(c.text.split()) > 3 and c.text.split()[3] in LOCAL_STYLES:
            computes[c.words[1]] = parse_compute(c.text, f"{where(c)}: ")
    globals_ = {name: (where(c), c.text.split()[5:]) for name, c in info.global_values.items()}
    primitives = {fix: w.primitive for fix, w in info.walls_defined
                  if w.primitive is not None and w.primitive[1] is not None
                  and len(w.primitive[1]) == PRIMITIVES[w.primitive[0]]}
    walls = [fix for fix, w in info.walls_defined if w.meshes]
    heat_gran = info.conductions
    wall_types = {fix: info.wall_type(fix) for fix in info.walls if info.wall_type(fix) is not None}
    clock = Clock(tuple(runs)) if runs else None
    # each set at its step counted through the runs; without a clock, at its step (as a steady clock counts)
    temperature_sets = [((count if clock else step), where, cmd) for (count, step), where, cmd in temperature_sets]
    return Script(timestep, computes, tuple(walls), tuple(warnings), box, tuple(heat_gran), primitives, globals_,
                  wall_types, tuple(temperature_sets), clock)


class ScriptDem:
    """The DEM values the script that wrote the dumps sets (``fix ... property/global``, plain
    numbers; ``Script.globals``), behind the part of the engine's interface that
    ``pyhost.engines.liggghts.box_input.script_dem_contacts`` reads: post's DEM contact of each material comes
    from the script as a run's comes from the engine, and a [materials.NAME.dem] table must
    agree with it. ``unread``: the values given as variables, which post cannot evaluate."""

    def __init__(self, script: Script):
        numbers = {}
        self.unread = {}
        for prop, (where, words) in script.globals.items():
            try:
                numbers[prop] = (where, words[0], [float(x) for x in words[1:]])
            except ValueError:
                self.unread[prop] = where
        self.values = numbers
        self.info = SimpleNamespace(globals=numbers, wall_type=script.wall_types.get)

    def _value(self, prop, k):
        where, style, v = self.values[prop]
        try:
            return v[k]
        except IndexError:
            raise ScriptError(f"{where}: property/global {prop} {style}: too few values for the dumps' atom types") \
                from None

    def type_values(self, prop, types) -> np.ndarray:
        return np.array([self._value(prop, int(t) - 1) for t in types])

    def type_pair_value(self, prop, a, b) -> float:
        n = int(self.values[prop][2][0]) if self.values[prop][2] else 0
        return self._value(prop, 1 + (a - 1) * n + (b - 1))


def script_dem_contacts_of(scene, script: Script) -> list:
    """The scene's materials, each with the DEM contact the script that wrote the dumps sets for
    its atom types (``box_input.script_dem_contacts`` on ``ScriptDem``; checked against a given
    dem table), the values given as variables named where one is missing."""
    dem = ScriptDem(script)
    try:
        return script_dem_contacts(scene, dem)
    except ScriptError as exc:
        unread = "; ".join(f"{where}: {prop}" for prop, where in dem.unread.items())
        raise ScriptError(f"{exc}" + (f" (post reads plain numbers; given as variables: {unread})" if unread
                                       else "")) from None
