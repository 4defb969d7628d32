"""A user's LIGGGHTS input script, read as LIGGGHTS reads it, so the host can run it command
by command and turn each ``run N`` into N coupled steps.

``read_script(path)`` gives the commands with their file and line: '#' comments dropped
(outside quotes), '&' continuation lines joined, ``include FILE`` expanded in place (paths
relative to the case folder, where the script runs), checked for what the host cannot run.
``Program`` is LIGGGHTS' own input loop over them, for the host to run: ``include``,
``label``, ``jump`` (SELF or another file, to a label), ``next`` (whose exhausted variable
skips the next jump), ``if`` (its branch chosen by LIGGGHTS, its commands run by the host,
so a ``run`` inside is coupled), ``run N every M "cmd"`` and ``quit``. ``$`` variables are
left to LIGGGHTS, which substitutes them when each command runs. The ``parse_*`` helpers read what the host must know about a command: the granular
walls (geometry of a primitive wall, meshes of a mesh wall), contact computes, heat/gran.
"""
from __future__ import annotations

import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

from pyhost.walls import PRIMITIVES


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


def script_commands(path: str | Path, folder: str | Path | None = None, _depth: int = 0,
                    expand: bool = True) -> list[Command]:
    """The commands of a LIGGGHTS script as LIGGGHTS reads them: '#' comments (outside quotes)
    dropped, '&' continuations joined, included files read in their place (``expand``; else
    the ``include`` commands stay); each with its file and first line. ``folder``: where
    relative include paths are found (default the script's own folder). ScriptError for a
    file that is missing or not text, an include nested more than 20 deep or of a variable
    file name, or a script ending inside a continuation."""
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
            if expand:
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
        _check(cmd, Path(folder) if folder is not None else Path(path).parent)
    return commands


def _check(cmd: Command, folder: Path) -> None:
    """One command of the script (or of an ``if``'s branch, checked as the script's own):
    ScriptError naming its line for what the host cannot run."""
    if cmd.name == "jump":
        _check_jump(cmd, folder)
    if cmd.name == "if":
        for branch in if_branches(cmd)[1]:
            for text in branch:
                _check(Command(text, cmd.file, cmd.line), folder)
    if cmd.name == "shell":
        _check_shell(cmd)
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
        parse_run(cmd)              # its forms the host cannot run refused before any engine time


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


def _check_shell(cmd: Command) -> None:
    """``shell`` runs in the host's own process, as LIGGGHTS runs it: ``mkdir``, ``rm``,
    ``putenv`` or a program. But ``shell cd`` would move the whole host (its output folder,
    the fluid case) along with LIGGGHTS' relative paths."""
    if cmd.words[1:2] == ["cd"]:
        raise ScriptError(f"{cmd.where()}: 'shell cd': it would move the host's own working folder with "
                          "LIGGGHTS'; give the script's paths relative to its folder instead")


def _check_jump(cmd: Command, folder: Path) -> None:
    """``jump SELF|FILE [label]``: the host finds the label or file itself, so it takes them as
    written (LIGGGHTS would substitute ``$`` variables), and the file must exist."""
    words = cmd.words
    if not 2 <= len(words) <= 3:
        raise ScriptError(f"{cmd.where()}: 'jump' takes a file (or SELF) and an optional label")
    if any("$" in w for w in words[1:]):
        raise ScriptError(f"{cmd.where()}: '{cmd.text}': a jump to a file or label given as a variable is not "
                          "supported (the host follows the script's jumps itself): write the name")
    if words[1] != "SELF" and not (folder / words[1]).is_file():
        raise ScriptError(f"{cmd.where()}: '{cmd.text}': no script {folder / words[1]}")


def if_branches(cmd: Command) -> tuple[list[str], list[list[str]]]:
    """An ``if "c1" then "cmd" ... [elif "c2" "cmd" ...] [else "cmd" ...]`` as its conditions
    (as written, without quotes) and each condition's commands, the else's last (an empty list
    where there is no else). ScriptError naming the line for a malformed one."""
    try:
        words = cmd.words
    except ValueError:
        raise ScriptError(f"{cmd.where()}: 'if' with unbalanced quotes") from None
    if len(words) < 4 or words[2] != "then":
        raise ScriptError(f"{cmd.where()}: 'if' needs a condition, 'then' and a command (LIGGGHTS: 'Illegal if command')")
    conditions, branches, k = [words[1]], [[]], 3
    while k < len(words):
        w = words[k]
        if w == "elif" and k + 2 < len(words):
            conditions.append(words[k + 1])
            branches.append([])
            k += 2
            continue
        if w == "else" and len(branches) == len(conditions):
            branches.append([])
        elif w in ("elif", "else") or not w.strip():
            raise ScriptError(f"{cmd.where()}: 'if' with a misplaced '{w}' or an empty command")
        else:
            branches[-1].append(w)
        k += 1
    if any(not b for b in branches):
        raise ScriptError(f"{cmd.where()}: 'if' with a branch without commands (LIGGGHTS: 'Illegal if command')")
    if len(branches) == len(conditions):
        branches.append([])
    return conditions, branches


def _if_commands(cmd: Command) -> list[str]:
    """The commands inside an ``if``'s branches, those of the ifs among them too."""
    found = []
    for branch in if_branches(cmd)[1]:
        for text in branch:
            found.append(text)
            if text.split(None, 1)[0] == "if":
                found += _if_commands(Command(text, cmd.file, cmd.line))
    return found


BOX = ("create_box", "read_data", "read_restart")
STATE = {"create_atoms", "delete_atoms", "displace_atoms", "set", "velocity", "read_dump", "change_box",
         "reset_timestep", "group", "write_restart", "write_data", "write_dump", "print", "shell", *BOX}
"""Commands whose effect is in LIGGGHTS' restart file (atoms and their values, groups, the box,
the step) or that only wrote output or acted on files (``shell``: its folders are there, and a
``shell rm`` done again would remove what the run wrote since): a restart does not replay them."""


def replay(commands: list[Command], upto: int, restart: Path) -> list[Command]:
    """The set-up of a script restarted at its command number ``upto`` of the commands it ran
    (``Program.trace``: loops unrolled, each ``if`` as the commands of its branch taken), a
    ``run`` that a checkpoint interrupted: commands[:upto] with the first box command
    (create_box, read_data, read_restart) replaced by ``read_restart`` of the checkpoint's
    file, what the file holds (``STATE``) left out, and the rest (regions, variables and their
    ``next``, fixes and unfixes under their ids, which take their state back from the file,
    computes, pair style, dumps) replayed in order; a dump or log to one file appends to it.
    Earlier runs stay in the list as markers (the host adds its own fixes at the first, as in
    the run that wrote the checkpoint); they simulate nothing."""
    out, box = [], False
    for cmd in commands[:upto]:
        name = cmd.name
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


@dataclass
class _Frame:
    """Commands being read: one file's (``file``; its includes not expanded) or an ``if``'s
    branch or a ``run ... every``'s chunks (``file`` None), and the next one's index."""

    commands: list
    pc: int = 0
    file: str | None = None


class Program:
    """LIGGGHTS' input loop over a script, for the host to run command by command: ``take()``
    gives the next command to run, having followed ``include``, ``label``, ``jump`` (SELF or
    another file, to the first matching label; skipped once after a ``next`` exhausted its
    variable, as LIGGGHTS does: ``skip_jump``) and ``quit`` (the end). An ``if`` and a
    ``run ... every`` come to the caller, who pushes the commands to run (``push``). ``trace``
    holds what the caller ran, in order (a restart replays it: ``replay``); ``state()`` and
    ``restore`` carry where the loop stands across a restart."""

    def __init__(self, path: str | Path, folder: str | Path):
        self.folder = Path(folder)
        self.frames = [self._file(Path(path))]
        self.skip_jump = False
        self.trace: list[Command] = []

    def _file(self, path: Path) -> _Frame:
        return _Frame(script_commands(path, self.folder, expand=False), 0, str(path))

    def take(self) -> Command | None:
        """The next command to run (never an include, label or jump), or None at the end."""
        while self.frames:
            frame = self.frames[-1]
            if frame.pc >= len(frame.commands):
                self.frames.pop()
                continue
            cmd = frame.commands[frame.pc]
            frame.pc += 1
            if cmd.name == "label":
                continue
            if cmd.name == "include":
                self.frames.append(self._file(self.folder / cmd.words[1]))
                continue
            if cmd.name == "jump":
                self._jump(cmd)
                continue
            if cmd.name == "quit":
                self.frames = []
                return None
            return cmd
        return None

    def plain_ahead(self) -> list[Command]:
        """The commands that come next in the frame being read, up to the first that is not
        plain (a run, if, jump, label, include or quit), without taking them."""
        frame = next((f for f in reversed(self.frames) if f.pc < len(f.commands)), None)
        if frame is None or frame is not self.frames[-1]:
            return []
        ahead = []
        for cmd in frame.commands[frame.pc:]:
            if cmd.name in ("run", "if", "jump", "label", "include", "quit"):
                break
            ahead.append(cmd)
        return ahead

    def peek(self) -> Command | None:
        """The command after ``plain_ahead`` in the same frame, if any."""
        frame = self.frames[-1] if self.frames else None
        if frame is None:
            return None
        k = frame.pc + len(self.plain_ahead())
        return frame.commands[k] if k < len(frame.commands) else None

    def push(self, cmd: Command, texts: list[str]) -> None:
        """Commands to run next (an ``if``'s branch, a ``run ... every``'s chunks), named by
        ``cmd``'s place in its file."""
        self.frames.append(_Frame([Command(t, cmd.file, cmd.line) for t in texts]))

    def _jump(self, cmd: Command) -> None:
        if self.skip_jump:                  # (LIGGGHTS' jump_skip: a loop's variable is exhausted)
            self.skip_jump = False
            return
        words = cmd.words
        while self.frames and self.frames[-1].file is None:
            self.frames.pop()               # the rest of an if's commands: LIGGGHTS skips them too
        if words[1] != "SELF":
            self.frames[-1] = self._file(self.folder / words[1])
        top = self.frames[-1]
        top.pc = 0
        if len(words) > 2:
            at = next((k for k, c in enumerate(top.commands) if c.name == "label" and c.words[1:2] == [words[2]]),
                      None)
            if at is None:
                raise ScriptError(f"{cmd.where()}: '{cmd.text}': no 'label {words[2]}' in {top.file} (LIGGGHTS: "
                                  "'Label wasn't found in input script')")
            top.pc = at + 1

    def state(self) -> dict:
        """Where the loop stands (JSON values)."""
        return dict(skip_jump=self.skip_jump, trace=[[c.text, c.file, c.line] for c in self.trace],
                    frames=[dict(file=f.file, pc=f.pc) if f.file is not None else
                            dict(commands=[[c.text, c.file, c.line] for c in f.commands], pc=f.pc)
                            for f in self.frames])

    @classmethod
    def restore(cls, state: dict, folder: str | Path) -> "Program":
        program = cls.__new__(cls)
        program.folder = Path(folder)
        program.skip_jump = state["skip_jump"]
        program.trace = [Command(*c) for c in state["trace"]]
        program.frames = []
        for f in state["frames"]:
            frame = (program._file(Path(f["file"])) if f.get("file") is not None
                     else _Frame([Command(*c) for c in f["commands"]]))
            frame.pc = f["pc"]
            program.frames.append(frame)
        return program


RANDOMS = {"insert": ("insert",), "particledistribution/discrete": ("distribution",),
           "particletemplate/sphere": ("template_insertion", "template_mc")}
"""Fix styles (insert/* as "insert") whose random generators a restart puts back, by the kind
``Liggghts.random_state`` knows them as."""


@dataclass(frozen=True)
class RunCommand:
    """``run N [upto] [pre yes|no] [post yes|no] [every M "cmd" ...]``: steps (possibly a
    $variable, evaluated by the host through LIGGGHTS), whether N is an end step, and with
    ``every`` the chunk M (steps, as written) and the commands run after each chunk; ``pre``:
    whether the run starts with a full set-up (LIGGGHTS' default, ``pre yes``)."""

    steps: str
    upto: bool
    every: str | None = None
    then: tuple = ()
    pre: bool = True


def parse_run(cmd: Command) -> RunCommand:
    words = cmd.words
    if len(words) < 2:
        raise ScriptError(f"{cmd.where()}: 'run' needs a number of steps")
    rest, upto, pre = words[2:], False, True
    while rest:
        key = rest.pop(0)
        if key == "upto":
            upto = True
        elif key == "pre" and rest:
            pre = rest.pop(0) != "no"
        elif key == "post" and rest:
            rest.pop(0)
        elif key in ("start", "stop") and rest:
            rest.pop(0)
        elif key == "every" and rest:
            every = rest.pop(0)
            then = () if rest == ["NULL"] else tuple(rest)     # (LIGGGHTS' run.cpp: NULL alone is none)
            if not rest:
                raise ScriptError(f"{cmd.where()}: 'run ... every {every}' needs its commands (or NULL)")
            if upto:
                raise ScriptError(f"{cmd.where()}: 'run ... upto ... every' is not supported by the host")
            return RunCommand(words[1], upto, every, then, pre)
        else:
            raise ScriptError(f"{cmd.where()}: 'run ... {key}' is not supported by the host (supported: "
                              "run N [upto] [pre yes|no] [post yes|no] [every M \"cmd\" ...])")
    return RunCommand(words[1], upto, pre=pre)


def step_after(cmd: Command, step: int | None) -> int | None:
    """The step a ``run N [upto]``, ``reset_timestep N`` or ``read_restart`` leaves the
    script at, from ``step`` before it, counted as written (None: unknown: a $variable, a
    restart file's step); ``step`` for any other command."""
    words = cmd.text.split()
    if words[0] not in ("run", "reset_timestep", "read_restart"):
        return step
    n = int(words[1]) if len(words) > 1 and words[1].isdigit() and words[0] != "read_restart" else None
    if n is None:
        return None
    return n if words[0] == "reset_timestep" or "upto" in words[2:] else None if step is None else step + n


def sets_temperature(cmd: Command) -> bool:
    """Whether the command is a ``set ... property/atom Temp VALUE``."""
    words = cmd.text.split()
    return words[0] == "set" and "property/atom" in words[:-2] and words[words.index("property/atom") + 1] == "Temp"


def script_couple_every(script: Path) -> tuple[int, str] | None:
    """``couple_every N`` of a CFDEM script's ``fix ID GROUP couple/cfd`` (the script's own text,
    not its includes) and where it is, or None."""
    for k, line in enumerate(script.read_text(errors="replace").splitlines(), 1):
        m = re.match(r"\s*fix\s+\S+\s+\S+\s+couple/cfd\b.*?\bcouple_every\s+(\d+)\b", line.split("#")[0])
        if m:
            return int(m.group(1)), f"{script}:{k}"
    return None


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


WRITES = {"dump", "dump_modify", "undump", "write_restart", "write_data", "write_dump", "log", "restart", "print"}
"""Commands whose file names are the run's output, not its input."""


def input_files(commands: list[Command], folder: str | Path) -> list[Path]:
    """The files a script's commands read, besides the script and its includes: each word that
    names an existing file (relative to ``folder``, where the script runs), such as an STL of
    ``fix mesh/surface file``, a ``read_data`` or ``read_restart`` file. A file the script
    itself writes (a dump, a restart, a fix's output file) is output, not input, even where a
    later command reads it; words with an unresolved ``$`` variable are left out."""
    folder = Path(folder)
    written, found = set(), []
    for cmd in commands:
        try:
            words = cmd.words
        except ValueError:
            continue                    # unbalanced quotes: LIGGGHTS says so itself
        if cmd.name in WRITES:
            written.update(words[1:])
        elif cmd.name == "fix" and not (len(words) > 3 and words[3].startswith("mesh/")):
            written.update(output_files(cmd))       # (a mesh's 'file' is its STL: read)
    for cmd in commands:
        if cmd.name in WRITES or cmd.file == "(host)":
            continue
        try:
            words = cmd.words
        except ValueError:
            continue
        for word in words[1:]:
            if "$" in word or word in written:
                continue
            path = (folder / word).resolve()
            if path.is_file() and path not in found:
                found.append(path)
    return found


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
    streams: list = field(default_factory=list)         # ids of the fix insert/stream defined now
    randoms: list = field(default_factory=list)         # "what id" of insertion's random generators
    fixes: dict = field(default_factory=dict)           # fix id -> the Command that defined it (defined now)
    # what post reads of the script that wrote the dumps (pyhost.engines.liggghts.dump_script), over the whole script
    timestep: str | None = None                         # the last 'timestep', as written
    computes: dict = field(default_factory=dict)        # compute id -> the Command that defined it
    global_values: dict = field(default_factory=dict)   # property/global name -> the Command that sets it
    conductions: list = field(default_factory=list)     # ids of every fix heat/gran defined, in order
    walls_defined: list = field(default_factory=list)   # (fix id, GranWall) of every wall/gran defined, in order

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

    def fix_named(self, message: str) -> Command | None:
        """The script's fix (defined now) that LIGGGHTS' error ``message`` names, by its id
        ("fix ID", "(id ID)", 'ID') or else by its style ("requested by heat/gran": the last
        defined of that style), so that a fix refused at a run's set-up is named at its own
        line, not the run's; None if it names none."""
        ours = [c for c in self.fixes.values() if c.file != "(host)"]
        for c in reversed(ours):
            i = re.escape(c.words[1])
            if re.search(rf"(?i:fix)\s+{i}\b|\(id\s+{i}\)|['\"]{i}['\"]", message):
                return c
        for c in reversed(ours):
            if "/" in c.words[3] and re.search(rf"(?<![\w/]){re.escape(c.words[3])}(?![\w/])", message):
                return c
        return None

    def _random(self, key: str, defined: bool) -> None:
        if key in self.randoms:
            self.randoms.remove(key)
        if defined:
            self.randoms.append(key)

    def learn(self, cmd: Command) -> None:
        """What a command run declares: the one reading of a script's commands, for runs (as
        each runs) and post (over the whole script). ScriptError for a wall the host cannot read."""
        w = cmd.words
        if w[0] == "timestep" and len(w) > 1:
            self.timestep = w[1]
        elif w[0] == "compute" and len(w) > 3:
            self.computes[w[1]] = cmd
        if w[0] == "fix" and len(w) >= 4:
            style = w[3]
            self.fixes[w[1]] = cmd
            if style == "wall/gran":
                self.walls[w[1]] = parse_wall(cmd)
                self.walls_defined.append((w[1], self.walls[w[1]]))
            elif style.startswith("mesh/surface") and "type" in w:
                self.mesh_types[w[1]] = int(w[w.index("type") + 1])
                if _keyword(w, "temperature") is not None:
                    self.mesh_temperatures[w[1]] = _keyword(w, "temperature")
            elif style == "heat/gran":
                self.heat_gran = w[1]
                self.conductions.append(w[1])
            elif style == "property/atom" and len(w) >= 5 and w[4] == "Temp":
                self.temp_fix = True
            elif style == "property/global" and len(w) >= 5:
                self.globals[w[4]] = w[1]
                if len(w) > 5:
                    self.global_values[w[4]] = cmd
            elif style.startswith("move/mesh") and w[1] not in self.mesh_motions:
                self.mesh_motions.append(w[1])
            elif style == "insert/stream" and w[1] not in self.streams:
                self.streams.append(w[1])
            for what in RANDOMS.get(style.split("/")[0] if style.startswith("insert/") else style, ()):
                self._random(f"{what} {w[1]}", True)
        elif w[0] == "unfix" and len(w) == 2:
            self.walls.pop(w[1], None)
            self.fixes.pop(w[1], None)
            if w[1] in self.mesh_motions:
                self.mesh_motions.remove(w[1])
            if w[1] in self.streams:
                self.streams.remove(w[1])
            self.randoms = [k for k in self.randoms if k.split(" ", 1)[1] != w[1] or k.startswith("region ")]
            if self.heat_gran == w[1]:
                self.heat_gran = None
        elif w[0] == "region" and len(w) >= 3:
            self._random("region " + w[1], w[2] != "delete")
        elif w[0] == "boundary" and len(w) >= 4:
            self.periodic = tuple(b == "p" for b in w[1:4])
