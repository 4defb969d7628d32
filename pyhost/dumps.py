"""Streaming reader of LIGGGHTS (and LAMMPS) dump files, frame by frame, in bounded memory.

Reads ``dump custom`` and ``dump atom`` text (``ITEM: ATOMS`` with any column order),
``dump local`` (``ITEM: ENTRIES``) of ``compute pair/gran/local`` and ``wall/gran/local``,
and ``dump custom/vtk`` legacy VTK files (through pyvista). Text files may be gzipped (told by
their first bytes, not their name); one file may hold many steps, or each step its own file.
Files are read in the order of their first timestep, not of their names (``dump.1000`` sorts
before ``dump.500`` by name).

``DumpReader(paths, ...)`` yields ``Frame``s: one numpy array of the frame's rows (parsed by
numpy's C loader, never row by row in Python), the box and its periodicity from
``ITEM: BOX BOUNDS``, and the column names. ``frame["radius"]``, ``frame["f_Temp"]`` (which also
finds ``f_Temp[0]``), ``frame.positions()`` (x y z, unwrapped or scaled), ``frame.vector("v")``.

A local dump's header names its columns only ``c_ID[k]``. What column k of compute ID holds
comes from the compute's keywords (``Compute``, e.g. from ``read_script`` of the LIGGGHTS input
that wrote the dumps): LIGGGHTS writes the keywords' groups in its code order, whatever order
they were typed in (``LOCAL_GROUPS``; measured in ../shared/ENGINES.md and read from
``compute_pair_gran_local.h`` of LIGGGHTS 3.8). A column that cannot be placed for sure is an
error, never a guess.

Any problem is a ``DumpError`` naming the file, the frame's timestep, the line and the problem.
With ``skip_bad_frames`` the reader records a warning (``reader.warnings``), skips the frame and
goes on from the next ``ITEM: TIMESTEP``.
"""
from __future__ import annotations

import glob
import gzip
import re
import shlex
import zlib
from dataclasses import dataclass, field, replace
from itertools import islice
from pathlib import Path

import numpy as np

from pyhost.script import Command, ScriptError, ScriptInfo, script_commands
from pyhost.walls import PRIMITIVES


class DumpError(ValueError):
    """A problem in a dump file: file, timestep of the frame (None before the first), line, problem."""

    def __init__(self, file, step, line, problem: str):
        self.file, self.step, self.line, self.problem = str(file), step, line, problem
        where = f"{file}: line {line}" if line else f"{file}"
        super().__init__(f"{where}: timestep {'?' if step is None else step}: {problem}")


# compute pair/gran/local and wall/gran/local of LIGGGHTS 3.8: keyword -> its columns (name,
# width), pair then wall, in the order LIGGGHTS writes them. "history" has the width of the pair
# style's history (unknown here). heatFlux is written last whatever else is asked for.
LOCAL_GROUPS = {
    "pos": ((("x_i", 3), ("x_j", 3)), (("x_contact", 3), ("x_i", 3))),
    "vel": ((("v_i", 3), ("v_j", 3)), (("v_wall", 3), ("v_i", 3))),
    "id": ((("id_i", 1), ("id_j", 1), ("periodic", 1)), (("mesh", 1), ("triangle", 1), ("id_i", 1))),
    "force": ((("force", 3),),) * 2,
    "force_normal": ((("force_normal", 3),),) * 2,
    "force_tangential": ((("force_tangential", 3),),) * 2,
    "torque": ((("torque", 3),),) * 2,
    "torque_normal": ((("torque_normal", 3),),) * 2,
    "torque_tangential": ((("torque_tangential", 3),),) * 2,
    "history": ((("history", None),),) * 2,
    "contactArea": ((("contact_area", 1),),) * 2,
    "delta": ((("delta", 1),),) * 2,
    "contactPoint": ((("contact_point", 3),),) * 2,
    "heatFlux": ((("heat_flux", 1),),) * 2,
}
LOCAL_DEFAULT = ("pos", "vel", "id", "force", "torque", "history", "contactArea")   # no keyword given
LOCAL_OPTIONS = {"verbose": 0, "extraSurfDistance": 1}      # keywords that add no column: values taken
LOCAL_STYLES = ("pair/gran/local", "wall/gran/local")


@dataclass(frozen=True)
class Compute:
    """A LIGGGHTS ``compute ID group STYLE keywords...`` of a local style."""

    id: str
    style: str
    keywords: tuple = ()

    @property
    def wall(self) -> bool:
        return self.style == "wall/gran/local"

    def columns(self) -> list:
        """(name, component) of each column the compute writes, in LIGGGHTS' order; a name
        of None stands for columns of unknown width (history), after which nothing is known."""
        words = [w for w in self.keywords if w in LOCAL_GROUPS] or list(LOCAL_DEFAULT)
        cols = []
        for kw in [k for k in LOCAL_GROUPS if k in words]:
            for name, width in LOCAL_GROUPS[kw][self.wall]:
                if width is None:
                    return cols + [(None, None)]
                cols += [(name, c) for c in range(width)] if width > 1 else [(name, None)]
        return cols


def parse_compute(text: str, where: str = "") -> Compute:
    """A compute from ``ID STYLE keywords...`` (or a whole ``compute ID group STYLE ...`` line)."""
    words = shlex.split(text.split("#")[0])
    if words and words[0] == "compute":
        words = words[1:2] + words[3:]
    if len(words) < 2 or words[1] not in LOCAL_STYLES:
        raise ValueError(f"{where}compute {text!r}: expected 'ID STYLE keyword...' with STYLE "
                         f"{' or '.join(LOCAL_STYLES)}")
    keywords, rest = [], iter(words[2:])
    for w in rest:
        if w in LOCAL_OPTIONS:
            list(islice(rest, LOCAL_OPTIONS[w]))
        elif w in LOCAL_GROUPS:
            keywords.append(w)
        else:
            raise ValueError(f"{where}compute {words[0]}: keyword {w!r} not understood; known: "
                             f"{', '.join(LOCAL_GROUPS)}")
    return Compute(words[0], words[1], tuple(keywords))


@dataclass(frozen=True)
class Clock:
    """The time of a script's steps across its runs, as LIGGGHTS steps them: each run's
    (first step, last step, time step [s], time at its first step [s]) in script order, a
    ``reset_timestep`` numbering the next run's steps anew and a ``timestep`` changing its dt.
    A frame's ``count`` is its step counted through the runs (never going back), from which
    ``time`` gives the time [s]. ``steady(dt)``: one run from step 0 at dt, without end."""

    runs: tuple

    @staticmethod
    def steady(dt: float) -> "Clock":
        return Clock(((0, float("inf"), dt, 0.0),))

    @property
    def offsets(self) -> np.ndarray:
        """The count at each run's first step."""
        return np.cumsum([0] + [last - first for first, last, _, _ in self.runs[:-1]])

    def time(self, count) -> np.ndarray | float:
        """The time [s] of a step's count (scalar or array); beyond the last run, at its dt."""
        offsets, count = self.offsets, np.asarray(count)
        r = np.maximum(np.searchsorted(offsets, count, side="right") - 1, 0)
        t0, dt = np.array([run[3] for run in self.runs]), np.array([run[2] for run in self.runs])
        t = t0[r] + (count - offsets[r]) * dt[r]
        return float(t) if t.ndim == 0 else t

    def counter(self):
        """``place(step)`` for the frames of one dump stream in their order: the step's count, the
        frame's run being the same as the last frame's or a later one (after a reset_timestep,
        one whose steps go back to it); None for a step no run from there holds."""
        offsets = self.offsets
        at = [0, None]                              # the run of the last frame, its step

        def place(step: int):
            r, last = at
            while r < len(self.runs):
                first, end = self.runs[r][:2]
                if first <= step <= end and (last is None or step >= last):
                    at[:] = r, step
                    return int(offsets[r] + step - first)
                r, last = r + 1, None
            return None

        return place


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


def local_compute(path) -> str:
    """The id of the compute whose rows a ``dump local`` file holds, from its first header
    (``ITEM: ENTRIES c_ID[1] ...``); DumpError if it is unreadable or not such a dump."""
    try:
        with open_text(path) as f:
            head = [f.readline() for _ in range(9)]
    except STREAM_ERRORS as exc:
        raise DumpError(path, None, 1, f"unreadable ({type(exc).__name__}: {exc})") from None
    if not head[8].startswith("ITEM: ENTRIES c_"):
        raise DumpError(path, None, 9, f"not a dump local of a compute: {head[8].strip()[:60]!r}")
    return head[8].split()[2].split("[")[0][2:]


def _is_number(words: list[str]) -> bool:
    try:
        float(words[0])
        return True
    except (IndexError, ValueError):
        return False


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
    (``pyhost.script.script_commands``: ``&`` continuations, ``#`` comments, included files
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
    timestep, computes, walls = None, {}, []
    heat_gran, primitives = [], {}
    globals_, info = {}, ScriptInfo()      # info: the walls and their atom types, as a run learns them
    step, temperature_sets, ran = 0, [], False    # the step reached (None: unknown, a $variable); any run yet
    runs, count, t = [], 0, 0.0     # the clock's runs so far, the steps counted through them, the time [s]
    for number, line in commands:
        line = substituted.get(number, line)
        words = line.split()
        where = f"{where_of[number]}: "
        try:
            info.learn(Command(line, read[number].file, read[number].line))
        except (ScriptError, ValueError):
            pass                        # a wall the run would refuse: post places none
        if words[0] == "timestep" and len(words) > 1:
            try:
                timestep = float(words[1])
            except ValueError:
                timestep = dt
        elif words[0] == "fix" and len(words) > 3 and words[3] == "heat/gran":
            heat_gran.append(words[1])
        elif words[0] == "fix" and len(words) > 5 and words[3] == "property/global":
            globals_[words[4]] = (where.rstrip(": "), words[5:])
        elif words[0] == "fix" and len(words) > 5 and words[3] == "wall/gran" and "primitive" in words:
            kind = next((w for w in words if w in PRIMITIVES), None)
            numbers = words[words.index(kind) + 1:][:PRIMITIVES[kind]] if kind else []
            try:
                if kind and len(numbers) == PRIMITIVES[kind]:
                    primitives[words[1]] = (kind, tuple(float(w) for w in numbers))
            except ValueError:
                pass                    # a $variable: post cannot place that wall
        elif words[0] == "compute" and len(words) > 3 and words[3] in LOCAL_STYLES:
            c = parse_compute(line, where)
            computes[c.id] = c
        elif words[0] == "fix" and len(words) > 3 and words[3] == "wall/gran" and "mesh" in words:
            walls.append(words[1])
        elif words[0] in ("run", "reset_timestep", "read_restart"):
            n = int(words[1]) if len(words) > 1 and words[1].isdigit() and words[0] != "read_restart" else None
            first = step
            step = (None if n is None else n if words[0] == "reset_timestep" or "upto" in words[2:]
                    else None if step is None else step + n)
            if words[0] == "run" and runs is not None:
                if first is None or step is None or timestep is None:
                    runs = None         # (a read_restart's step, a run of $variable steps: no clock)
                elif step > first:
                    runs.append((first, step, timestep, t))
                    count, t = count + step - first, t + (step - first) * timestep
            ran = ran or words[0] == "run"
        elif (words[0] == "set" and ran and "property/atom" in words[:-2]
              and words[words.index("property/atom") + 1] == "Temp"):     # (before any run: the first frame's)
            temperature_sets.append(((count, step), where.rstrip(": "), " ".join(words)))
    wall_types = {fix: info.wall_type(fix) for fix in info.walls if info.wall_type(fix) is not None}
    clock = Clock(tuple(runs)) if runs else None
    # each set at its step counted through the runs; without a clock, at its step (as a steady clock counts)
    temperature_sets = [((count if clock else step), where, cmd) for (count, step), where, cmd in temperature_sets]
    return Script(timestep, computes, tuple(walls), tuple(warnings), box, tuple(heat_gran), primitives, globals_,
                  wall_types, tuple(temperature_sets), clock)


@dataclass(frozen=True, eq=False)
class Frame:
    """One dump frame: rows ``data`` (n, columns) of float64, named by ``columns``."""

    file: str
    line: int                       # line of its ITEM: TIMESTEP (0 for VTK)
    step: int                       # its step counted through the script's runs (``Clock``; the file's without one)
    time: float | None              # [s] (``Clock.time``), None without a clock or dt
    box: np.ndarray | None          # (3, 2) lo hi [m]; None for VTK (no box in the file)
    periodic: tuple                 # (bool, bool, bool)
    columns: tuple
    data: np.ndarray
    kind: str = "atoms"             # atoms, pair, wall, local
    groups: dict = field(default_factory=dict)     # name -> column indices of a group (local)
    timestep: int | None = None     # the step as the file numbers it (None: ``step``)

    def __len__(self) -> int:
        return len(self.data)

    def index(self, name: str):
        """Column index (int) or indices (list) of name; None if absent. ``f_X`` finds ``f_X[0]``."""
        if name in self.groups:
            return self.groups[name]
        for candidate in (name, f"{name}[0]", name[:-3] if name.endswith("[0]") else None):
            if candidate in self.columns:
                return self.columns.index(candidate)
        return None

    def __contains__(self, name: str) -> bool:
        return self.index(name) is not None

    def __getitem__(self, name: str) -> np.ndarray:
        k = self.index(name)
        if k is None and not len(self.data):       # a frame without rows (a VTK file of 0 points has no names)
            return np.empty((0, 3) if name in self.groups else 0)
        if k is None:
            raise KeyError(f"{self.file}: timestep {self.step}: no column {name!r}; columns: {' '.join(self.columns)}")
        return self.data[:, k]

    def vector(self, name: str) -> np.ndarray:
        """(n, 3) of group name (local), or of columns name+x, name+y, name+z (vx vy vz)."""
        if name in self.groups:
            return self.data[:, self.groups[name]]
        return np.stack([self[name + c] for c in "xyz"], axis=1)

    def positions(self) -> np.ndarray:
        """(n, 3) centres [m] from x y z, xu yu zu, or the scaled xs ys zs / xsu ysu zsu."""
        if not len(self.data):
            return np.empty((0, 3))
        for suffix in ("", "u"):
            if all(c + suffix in self.columns for c in "xyz"):
                return np.stack([self[c + suffix] for c in "xyz"], axis=1)
            if all(c + "s" + suffix in self.columns for c in "xyz"):
                s = np.stack([self[c + "s" + suffix] for c in "xyz"], axis=1)
                return self.box[:, 0] + s * (self.box[:, 1] - self.box[:, 0])
        raise KeyError(f"{self.file}: timestep {self.step}: no positions (x y z, xu.., xs..)")


POSITION_SETS = ("x y z", "xu yu zu", "xs ys zs", "xsu ysu zsu")
REQUIRED = {"id": ("id",), "type": ("type",), "position": POSITION_SETS, "velocity": ("vx vy vz",),
            "radius": ("radius",)}
"""Columns post-processing needs, each satisfied by any of the column sets listed."""


def _missing(columns, require) -> list:
    have = set(columns)
    return [name for name in require
            if not any(set(option.split()) <= have for option in REQUIRED[name])]


def open_text(path: Path):
    """Text stream of a plain or gzipped file (gzip told by its magic bytes)."""
    with open(path, "rb") as f:
        magic = f.read(2)
    if magic == b"\x1f\x8b":
        return gzip.open(path, "rt", encoding="ascii", errors="strict")
    return open(path, encoding="ascii", errors="strict")


STREAM_ERRORS = (EOFError, gzip.BadGzipFile, zlib.error, UnicodeDecodeError, OSError)


class _Lines:
    """Lines of an open file with their 1-based numbers and a pushback for resynchronising."""

    def __init__(self, stream):
        self.stream, self.number, self.back = stream, 0, []

    def next(self) -> str | None:
        self.number += 1
        if self.back:
            return self.back.pop()
        line = self.stream.readline()
        if not line:
            self.number -= 1
            return None
        return line

    def take(self, n: int) -> list:
        lines = []
        while self.back and len(lines) < n:
            lines.append(self.back.pop())
        lines += islice(self.stream, n - len(lines))
        self.number += len(lines)
        return lines

    def push(self, lines: list) -> None:
        self.back.extend(reversed(lines))
        self.number -= len(lines)


VTK_SUFFIXES = (".vtk", ".vtp", ".vtu")


def expand(paths) -> list:
    """Paths with shell wildcards expanded (for quoted ``'post/dump.*'``). A wildcard skips
    the ``*boundingBox*.vtk`` files LIGGGHTS' custom/vtk writes beside each frame (they hold
    the box only: ``heatGran_*.vtk`` matches them too)."""
    out = []
    for p in map(str, paths):
        hits = sorted(glob.glob(p)) if glob.has_magic(p) else [p]
        if glob.has_magic(p):
            hits = [h for h in hits if not (Path(h).suffix == ".vtk" and "boundingBox" in Path(h).name)]
        if not hits:
            raise DumpError(p, None, 0, "no file matches")
        for h in hits:
            if not Path(h).is_file():
                raise DumpError(h, None, 0, "no such file")
        out += hits
    return [Path(h) for h in out]


def _vtk_step(path: Path) -> int:
    digits = re.findall(r"\d+", path.name[: -len(path.suffix)])
    if not digits:
        raise DumpError(path, None, 0, "a VTK dump's timestep is read from its name, and this one has no number")
    return int(digits[-1])


def processor_parts(files) -> tuple[list, dict]:
    """A ``dump local`` whose file name has ``%`` (an MPI run's one file per processor):
    LIGGGHTS 3.8 writes its header, with processor 0's row count, into processor 0's file
    only; the other processors' files hold bare rows (or nothing). Each such file goes
    with the file of the same name but for a 0 in place of its processor number, whose
    frame it completes: (the files with a header, {that file: its processors' files})."""
    heads, bare = [], []
    for p in files:
        if p.suffix.lower() in VTK_SUFFIXES:
            heads.append(p)
            continue
        try:
            with open_text(p) as f:
                first = f.readline()
        except STREAM_ERRORS:
            heads.append(p)             # (its error is said when it is read)
            continue
        (bare if not first.startswith("ITEM:") and (not first.strip() or _is_number(first.split()))
         else heads).append(p)
    parts, header_of = {}, {}
    for h in heads:
        tokens = re.split(r"(\d+)", h.name)
        for k in range(1, len(tokens), 2):
            if tokens[k] == "0":
                header_of.setdefault((h.parent, tuple(tokens[:k]), tuple(tokens[k + 1:])), h)
    for p in bare:
        tokens = re.split(r"(\d+)", p.name)
        h = next((header_of[key] for k in range(1, len(tokens), 2) if tokens[k] != "0"
                  and (key := (p.parent, tuple(tokens[:k]), tuple(tokens[k + 1:]))) in header_of), None)
        if h is None:
            heads.append(p)             # (refused when read: no header, no processor 0's file given)
        else:
            parts.setdefault(h, []).append(p)
    return heads, parts


class DumpReader:
    """Frames of dump files in timestep order: ``for frame in DumpReader(paths): ...``.

    ``computes``: id -> Compute for local dumps (``read_script(...).computes``); ``clock`` (the
    script's ``Clock``, through its time step changes and resets) or else ``dt`` [s] gives each
    frame its time and its step counted through the runs; ``require``: names of ``REQUIRED`` an atom frame must hold;
    ``skip_bad_frames``: warn (``self.warnings``) and go on instead of raising.
    """

    def __init__(self, paths, computes: dict | None = None, dt: float | None = None, require=(),
                 skip_bad_frames: bool = False, clock: Clock | None = None):
        self.computes, self.require = dict(computes or {}), tuple(require)
        self.clock = clock if clock is not None else Clock.steady(dt) if dt is not None else None
        self.skip, self.warnings = skip_bad_frames, []
        files = expand(paths)
        boxes = [p for p in files if p.suffix.lower() in VTK_SUFFIXES and "_boundingBox_" in p.name]
        if boxes:
            self.warnings.append(f"{len(boxes)} box outlines of dump custom/vtk (*_boundingBox_*) not read "
                                 "as particle frames")
        files, self.parts = processor_parts([p for p in files if p not in boxes])
        self.files = self._order(files)

    def _with_parts(self, path: Path, frames):
        """The frames of ``path``, each completed by its processors' files' rows (``parts``)."""
        parts = self.parts.get(path)
        if not parts:
            yield from frames
            return
        frames = list(frames)
        if len(frames) != 1:
            self._fail(DumpError(parts[0], None, 1, f"another processor's part of {path.name} (a dump local with "
                                 f"'%' in its file name), whose {len(frames)} frames it cannot be split into: "
                                 "LIGGGHTS writes the header into processor 0's file only; write one file per step "
                                 "and processor ('dump ... local N post/pair.*.%')"))
            yield from frames
            return
        frame, rows = frames[0], [frames[0].data]
        for part in parts:
            try:
                with open_text(part) as f:
                    body = [ln for ln in f.read().splitlines() if ln.strip()]
                error = lambda problem, row, part=part: DumpError(part, frame.step, row + 1, problem)
                data = _parse(body, len(frame.columns), error)
                if frame.groups:
                    self._check_local(data, frame.columns, frame.groups, error)
            except _HeaderInRows as header:
                self._fail(DumpError(part, frame.step, header.row + 1, "a header among the processor's rows"))
                continue
            except DumpError as exc:
                self._fail(exc)
                continue
            except STREAM_ERRORS as exc:
                self._fail(DumpError(part, frame.step, 0, f"unreadable ({type(exc).__name__}: {exc})"))
                continue
            rows.append(data)
        yield replace(frame, data=np.concatenate(rows))

    def _fail(self, error: DumpError) -> None:
        if not self.skip:
            raise error
        self.warnings.append(f"skipped: {error}")

    def _first_step(self, path: Path):
        if path.suffix.lower() in VTK_SUFFIXES:
            return _vtk_step(path)
        try:
            with open_text(path) as f:
                head = [f.readline() for _ in range(2)]
        except STREAM_ERRORS as exc:
            raise DumpError(path, None, 1, f"unreadable ({type(exc).__name__}: {exc})") from None
        if not head[0]:
            raise DumpError(path, None, 0, "empty file")
        if head[0].strip() != "ITEM: TIMESTEP":
            bare = _is_number(head[0].split())
            raise DumpError(path, None, 1, f"not a LIGGGHTS dump: first line {head[0].strip()[:60]!r}, "
                                           "expected 'ITEM: TIMESTEP'"
                            + ("; rows without a header are another processor's part of a dump local with '%' in "
                               "its file name: give processor 0's file (the same name with 0 for the processor) "
                               "with it" if bare else ""))
        try:
            return int(head[1])
        except ValueError:
            raise DumpError(path, None, 2, f"timestep {head[1].strip()[:40]!r} is not an integer") from None

    def _order(self, paths) -> list:
        keyed = []
        for p in paths:
            try:
                keyed.append((self._first_step(p), str(p), p))
            except DumpError as exc:
                self._fail(exc)
        return [p for _, _, p in sorted(keyed)]

    def __iter__(self):
        last = None                                     # (count, file, step) of the previous frame
        place = self.clock.counter() if self.clock is not None else None
        for path in self.files:
            frames = self._vtk(path) if path.suffix.lower() in VTK_SUFFIXES else self._with_parts(path, self._text(path))
            for frame in frames:
                count = frame.step if place is None else place(frame.step)
                if count is None or last is not None and count < last[0]:
                    resets = self.clock is not None and len(self.clock.runs) > 1
                    self._fail(DumpError(frame.file, frame.step, frame.line,
                                         f"timestep goes backwards (previous frame: timestep {last[2]} in {last[1]})"
                                         + ("" if resets else ": a script's reset_timestep is followed with --script")
                                         if last is not None else "timestep before the script's first run"))
                    continue
                if last is not None and count == last[0]:
                    self.warnings.append(f"{frame.file}: line {frame.line}: timestep {frame.step} again: "
                                         "frame skipped")
                    continue
                last = (count, frame.file, frame.step)
                yield replace(frame, step=count, timestep=frame.step,
                              time=None if self.clock is None else self.clock.time(count))

    def _text(self, path: Path):
        try:
            stream = open_text(path)
        except OSError as exc:
            self._fail(DumpError(path, None, 0, f"cannot open: {exc.strerror}"))
            return
        with stream:
            lines = _Lines(stream)
            while True:
                start = lines.number + 1
                try:
                    frame = self._frame(lines, path)
                except DumpError as exc:
                    self._fail(exc)
                    if not self._resync(lines, path):
                        return
                    continue
                except STREAM_ERRORS as exc:
                    self._fail(DumpError(path, None, lines.number + 1, f"truncated or corrupt stream after line "
                                         f"{lines.number} ({type(exc).__name__}: {exc})"))
                    return
                if frame is None:
                    if lines.number + 1 == start == 1:
                        self._fail(DumpError(path, None, 0, "empty file"))
                    return
                yield frame

    def _resync(self, lines: _Lines, path: Path) -> bool:
        """After a bad frame: on to the next ITEM: TIMESTEP; False at the end of the file."""
        try:
            while (line := lines.next()) is not None:
                if line.startswith("ITEM: TIMESTEP"):
                    lines.push([line])
                    return True
        except STREAM_ERRORS as exc:
            self.warnings.append(f"{path}: line {lines.number + 1}: truncated or corrupt stream "
                                 f"({type(exc).__name__}: {exc}): rest of the file skipped")
        return False

    def _frame(self, lines: _Lines, path: Path) -> Frame | None:
        line = lines.next()
        if line is None:
            return None
        start, step = lines.number, None

        def error(problem, number=None):
            return DumpError(path, step, lines.number if number is None else number, problem)

        def item(expected):
            text = lines.next()
            if text is None:
                raise error(f"file ends where '{expected}' was expected (truncated)", lines.number + 1)
            if not text.startswith(expected):
                raise error(f"expected '{expected}', got {text.strip()[:60]!r}")
            return text[len(expected):].split()

        lines.push([line])
        item("ITEM: TIMESTEP")
        step = self._integer(lines, error, "timestep")
        head = lines.next()
        if head is None or not head.startswith("ITEM: NUMBER OF "):
            raise error("expected 'ITEM: NUMBER OF ATOMS' or 'ITEM: NUMBER OF ENTRIES', got "
                        f"{'end of file' if head is None else repr(head.strip()[:60])}")
        local = head.strip() == "ITEM: NUMBER OF ENTRIES"
        n = self._integer(lines, error, "row count")
        if n < 0:
            raise error(f"negative row count {n}")
        flags = item("ITEM: BOX BOUNDS")
        bounds = flags[-3:]
        if flags[:3] == ["xy", "xz", "yz"]:
            raise error("triclinic box: not supported")
        if len(bounds) != 3 or any(len(b) != 2 or set(b) - set("pfsm") for b in bounds):
            raise error(f"box boundary flags {' '.join(flags)!r} not understood (expected e.g. 'pp pp ff')")
        box = np.empty((3, 2))
        for k in range(3):
            text = lines.next()
            try:
                box[k] = [float(w) for w in (text or "").split()[:2]]
            except ValueError:
                raise error(f"box bounds {text.strip()[:60]!r}: two numbers expected") from None
        columns = item("ITEM: ENTRIES" if local else "ITEM: ATOMS")
        if not columns:
            raise error("header names no column")
        kind, groups = ("atoms", {}) if not local else self._local_layout(columns, error)
        if kind == "atoms" and self.require and (missing := _missing(columns, self.require)):
            raise error(f"required column missing: {', '.join(missing)} (columns: {' '.join(columns)})")
        body = lines.take(n)
        first = lines.number - len(body) + 1
        try:
            data = _parse(body, len(columns), lambda problem, row: error(problem, first + row))
        except _HeaderInRows as short:
            lines.push(body[short.row:])
            raise error(f"frame has {short.row} rows, its header says {n} (truncated)", first + short.row) from None
        if len(body) < n:
            raise error(f"file ends after {len(body)} rows of {n} (truncated)", first + len(body))
        if kind == "atoms":
            self._check_atoms(data, columns, lambda problem, row: error(problem, first + row))
        elif groups:
            self._check_local(data, columns, groups, lambda problem, row: error(problem, first + row))
        periodic = tuple(b == "pp" for b in bounds)
        return Frame(str(path), start, step, None, box, periodic, tuple(columns), data, kind, groups)

    @staticmethod
    def _integer(lines, error, what) -> int:
        text = lines.next()
        try:
            return int(text)
        except (TypeError, ValueError):
            raise error(f"{what} {'missing' if text is None else repr(text.strip()[:40])}: an integer expected") from None

    def _local_layout(self, columns, error):
        """Kind (pair, wall, local) and name -> column indices from the computes' keywords."""
        meaning, styles = [], set()
        for k, name in enumerate(columns):
            m = re.fullmatch(r"c_([^\[\]]+)\[(\d+)\]", name)
            if not m:
                meaning.append((name, None))
                continue
            cid, col = m.group(1), int(m.group(2))
            if cid not in self.computes:
                raise error(f"column {name}: what compute {cid}'s columns hold needs its keywords "
                            f"(--script with its 'compute {cid} ...' line, or --compute '{cid} STYLE keywords')")
            compute = self.computes[cid]
            styles.add(compute.style)
            cols = compute.columns()
            known = [c for c in cols if c[0] is not None]
            if col < 1 or (col > len(known) and len(known) == len(cols)):
                raise error(f"column {name}: compute {cid} ({compute.style} {' '.join(compute.keywords)}) "
                            f"writes {len(cols)} columns, not {col}: keywords do not match the dump")
            if col > len(known):
                raise error(f"column {name}: follows compute {cid}'s 'history', whose width depends on the "
                            "pair style: its meaning is ambiguous")
            meaning.append(known[col - 1])
        if len(styles) > 1:
            raise error("one dump mixes pair/gran/local and wall/gran/local columns")
        self._check_cut(columns, error)
        groups = {}
        for k, (name, comp) in enumerate(meaning):
            groups.setdefault(name, {})[comp] = k
        layout = {name: (parts[None] if None in parts else [parts[c] for c in sorted(parts)])
                  for name, parts in groups.items() if None in parts or len(parts) == 3}
        kind = "local" if not styles else ("wall" if styles == {"wall/gran/local"} else "pair")
        return kind, layout

    def _check_cut(self, columns, error) -> None:
        """A dump that lists a compute's columns 1..N where N ends inside one of its keyword's
        groups (5 of the 6 'vel' columns): written by a compute of other keywords than the
        ones given (a user dumps whole groups)."""
        listed = {}
        for name in columns:
            if m := re.fullmatch(r"c_([^\[\]]+)\[(\d+)\]", name):
                listed.setdefault(m.group(1), []).append(int(m.group(2)))
        for cid, cols in listed.items():
            known = [c for c in self.computes[cid].columns() if c[0] is not None]
            n = len(cols)
            if sorted(cols) == list(range(1, n + 1)) and n < len(known) and known[n - 1][0] == known[n][0]:
                compute = self.computes[cid]
                raise error(f"the dump has columns 1-{n} of compute {cid}, which ends inside its "
                            f"'{known[n][0]}' columns by the keywords {compute.style} {' '.join(compute.keywords)} "
                            f"({len(known)} columns): the keywords (--script, --compute) are not those of the "
                            "compute that wrote this dump")

    # columns that hold whole numbers, and their least value, whatever the compute's keywords
    _WHOLE = {"id_i": 1, "id_j": 1, "periodic": 0, "mesh": 0, "triangle": 0}

    def _check_local(self, data, columns, groups, error) -> None:
        """Contact rows read by the computes' keywords (from --script or --compute) must hold
        ids where the keywords place them: keywords that are not those the dump was written
        with would otherwise reinterpret its columns without a word."""
        for name, least in self._WHOLE.items():
            k = groups.get(name)
            if not isinstance(k, int) or not len(data):
                continue
            bad = np.flatnonzero((data[:, k] != np.round(data[:, k])) | (data[:, k] < least))
            if len(bad):
                raise error(f"column {columns[k]} should hold {name} by the compute's keywords, but holds "
                            f"{data[bad[0], k]:g}: the keywords (--script, --compute) are not those of the "
                            "compute that wrote this dump", bad[0])

    def _check_atoms(self, data, columns, error) -> None:
        if "radius" in columns:
            bad = np.flatnonzero(data[:, columns.index("radius")] < 0)
            if len(bad):
                raise error(f"negative radius {data[bad[0], columns.index('radius')]:g}", bad[0])
        if "id" in columns:
            ids = data[:, columns.index("id")]
            _, first = np.unique(ids, return_index=True)
            if len(first) < len(ids):
                row = int(np.setdiff1d(np.arange(len(ids)), first).min())
                raise error(f"duplicate id {ids[row]:.0f} in one frame", row)

    def _vtk(self, path: Path):
        import pyvista

        step = _vtk_step(path)
        try:
            with pyvista.vtk_verbosity("off"):      # an empty frame (0 points) is no problem here
                mesh = pyvista.read(str(path))
        except Exception as exc:          # VTK's reader raises assorted types for broken files
            self._fail(DumpError(path, step, 0, f"not a readable VTK file ({type(exc).__name__}: {exc})"))
            return
        columns, arrays = ["x", "y", "z"], [np.asarray(mesh.points, float)]
        for name in mesh.point_data.keys():
            a = np.asarray(mesh.point_data[name], float)
            if a.ndim == 2 and a.shape[1] == 3:
                columns += [name + c for c in "xyz"] if name != "v" else ["vx", "vy", "vz"]
            else:
                columns.append(name)
            arrays.append(a.reshape(len(a), -1))
        data = np.concatenate(arrays, axis=1) if mesh.n_points else np.empty((0, len(columns)))
        error = lambda problem, row: DumpError(path, step, 0, f"point {row}: {problem}")
        try:
            if mesh.n_points and (missing := _missing(columns, self.require)):
                raise DumpError(path, step, 0, f"required column missing: {', '.join(missing)} "
                                               f"(point data: {' '.join(mesh.point_data.keys())})")
            bad = np.flatnonzero(~np.isfinite(data).all(axis=1))
            if len(bad):
                raise error("NaN or infinite value", bad[0])
            self._check_atoms(data, columns, error)
        except DumpError as exc:
            self._fail(exc)
            return
        yield Frame(str(path), 0, step, None, None, (False, False, False), tuple(columns), data)


class _HeaderInRows(Exception):
    def __init__(self, row):
        self.row = row


def _parse(body: list, ncols: int, error) -> np.ndarray:
    """Rows of numbers (len(body), ncols) by numpy's C parser; on failure the first bad row
    is found and named (wrong column count, non-numeric token, NaN or infinity), or
    _HeaderInRows raised where the next frame's header starts among the rows (a short frame)."""
    if not body:
        return np.empty((0, ncols))
    try:
        data = np.loadtxt(body, dtype=float, comments=None, ndmin=2)
        if data.shape[1] == ncols and np.isfinite(data).all():
            return data
    except ValueError:
        pass
    for k, text in enumerate(body):
        if text.startswith("ITEM:"):
            raise _HeaderInRows(k)
        words = text.split()
        if len(words) != ncols:
            raise error(f"{len(words)} values in a row, the header names {ncols} columns", k)
        for w in words:
            try:
                value = float(w)
            except ValueError:
                raise error(f"non-numeric value {w[:30]!r}", k) from None
            if not np.isfinite(value):
                raise error(f"non-finite value {w!r}", k)
    raise AssertionError("loadtxt refused rows that parse one by one")
