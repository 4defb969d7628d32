"""CFDEM's liggghtsCommands: the LIGGGHTS commands a CFDEM case's coupling runs between its
coupling steps (``constant/liggghtsCommands``), read as CFDEMcoupling-PUBLIC reads them
(``src/lagrangian/cfdemParticle/subModels/liggghtsCommandModel``).

Its ``liggghtsCommandModels`` list names, in order:

- ``runLiggghts``: the DEM's run of each coupling step, which the host's loop does itself
  (``preNo`` is a speed-up of LIGGGHTS' set-up only); with ``runFirst on`` CFDEM runs the DEM at
  the first coupling step only, which the host does not (refused);
- ``writeLiggghts``: ``write_restart PATH/NAME`` at every write time of the fluid (every
  ``writeEvery``-th), or at the last coupling step only (``writeLastOnly on``); PATH defaults to
  ``../DEM``, NAME to ``liggghts.restartCFDEM``, with ``_`` and the fluid's time appended
  unless ``overwrite on``;
- ``execute``: a command composed of the words of ``executeProps<i>`` (i: its place in the
  list, from 0), run at the first or last coupling step, every coupling step, every write
  time, or every ``timeInterval`` coupling steps from ``startTime`` to ``endTime`` [s].

Any other model (readLiggghtsData, setDEMGravity, ...) is refused: a case whose commands the
host would leave out would end with exit 0 and another answer. In CFDEM the models run after
the coupling step's DEM run, in the list's order, before the fluid gets the particles: so here
(``pyhost.effects.case_commands``). SI units; times in s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from pyhost.engines.liggghts.script import host_fix_refusal

SMALL = 1e-15
"""OpenFOAM's SMALL, which CFDEM adds before each floor of a time over the coupling interval."""

KNOWN = ("runLiggghts", "writeLiggghts", "execute")


class CaseCommandsError(ValueError):
    """A liggghtsCommands the host cannot run as CFDEM would; the message names the entry."""


@dataclass(frozen=True)
class CaseCommand:
    """One command of a liggghtsCommands: ``text`` (the fluid's time appended at each run when
    ``stamp``), when it runs (``when``: "first", "last", "coupling", "write" or "interval";
    "interval" with ``times`` = (startTime, endTime, timeInterval), the last in coupling steps;
    "write" every ``write_every``-th write time) and where it is written (``file``, ``line``:
    its Props dictionary's, or the model's name in the list's)."""
    text: str
    stamp: bool
    when: str
    file: str
    line: int
    times: tuple = ()
    write_every: int = 1

    @property
    def where(self) -> str:
        return f"{self.file}:{self.line}"

    def command(self, t: float) -> str:
        """The command at fluid time ``t`` [s] (CFDEM's ``%f`` time stamp)."""
        return self.text + (f"{t:f}" if self.stamp else "")

    def due(self, k: int, last: int, writes: int, wrote: bool, start: float, dt: float, every: int) -> bool:
        """Whether it runs at coupling step ``k`` (from 1, as CFDEM counts them from its start):
        ``last``, the last coupling step; ``writes``, the fluid's write times passed up to this
        step (this one included when ``wrote``); ``start`` [s], the fluid's startTime; ``dt``
        [s], the DEM's time step; ``every``, DEM steps per coupling step
        (liggghtsCommandModel::checkTimeSettings and runThisCommand)."""
        if self.when == "write":
            return wrote and (writes - 1) % self.write_every == 0
        if self.when == "first":
            first, final, step = 1, 1, 0
        elif self.when == "last":
            first, final, step = last, last, 0
        elif self.when == "coupling":
            first, final, step = 1, math.inf, 1
        else:
            t0, t1, step = self.times
            first = math.floor((t0 + SMALL - start) / dt / every)
            final = math.floor((t1 + SMALL - start) / dt / every)
            step = math.floor(step)
        k0 = max(first, 1)                  # (CFDEM's nextRun starts at -1: its first run is first's step)
        if not k0 <= k <= final:
            return False
        return k == k0 or (step > 0 and (k - k0) % step == 0)


def compose(words: list, scalars: list, labels: list, couple_every: int) -> tuple[str, bool]:
    """The command of an ``execute``'s word list (liggghtsCommandModel::parseCommandList):
    dot, dotdot, slash, noBlanks/blanks, number (the next of ``scalars``, %f), label (of
    ``labels``, %d), $couplingInterval; returns (text, timeStamp asked)."""
    text, blank, stamp, numbers, ints = "", True, False, iter(scalars), iter(labels)
    for word in map(str, words):
        add = {"dot": ".", "dotdot": "..", "slash": "/"}.get(word, word)
        if word == "$couplingInterval":
            add = str(couple_every)
        elif word == "noBlanks":
            add, blank = "", False
        elif word == "blanks":
            add, blank = "", True
        elif word == "timeStamp":
            add, stamp = "", True
        elif word == "number":
            add = f"{float(next(numbers)):f}"
        elif word == "label":
            add = f"{int(next(ints))}"
        text += add + (" " if blank else "")
    return text, stamp


def _switch(props, key: str, where: str) -> bool:
    value = props.get(key)
    if isinstance(value, bool):
        return value
    raise CaseCommandsError(f"{where}: {key}: CFDEM needs on or off here, got {value!r}")


def _when(props, where: str) -> tuple[str, tuple]:
    """liggghtsCommandModel::checkTimeMode: runFirst, else runLast, else runEveryCouplingStep,
    else runEveryWriteStep, else startTime, endTime and timeInterval."""
    for key, when in (("runFirst", "first"), ("runLast", "last"), ("runEveryCouplingStep", "coupling"),
                      ("runEveryWriteStep", "write")):
        if _switch(props, key, where):
            return when, ()
    try:
        return "interval", tuple(float(props[k]) for k in ("startTime", "endTime", "timeInterval"))
    except (KeyError, TypeError, ValueError):
        raise CaseCommandsError(f"{where}: every run switch is off, so CFDEM needs startTime, endTime and "
                                "timeInterval (coupling steps) as numbers") from None


def read_commands(case: str | Path, couple_every: int) -> list[CaseCommand]:
    """The commands of a CFDEM case's constant/liggghtsCommands besides its coupled run, in the
    order CFDEM runs them; [] without the file. CaseCommandsError for a model the host does not
    run, or a dictionary CFDEM would refuse."""
    path = Path(case) / "constant" / "liggghtsCommands"
    if not path.is_file():
        return []
    from pyhost.engines.fluid_case import cfdem_dict, entry_line   # (foamlib: 0.1-0.2 s, CFDEM cases only)

    f = cfdem_dict(path)
    models = [str(m) for m in (f.get("liggghtsCommandModels") or [])]
    if "runLiggghts" not in models:
        raise CaseCommandsError(f"{path}: liggghtsCommandModels has no runLiggghts: CFDEM would not run the DEM "
                                "at all; the host always does (add runLiggghts)")
    found = []
    for i, model in enumerate(models):
        if model not in KNOWN:
            raise CaseCommandsError(f"{path}: liggghtsCommandModels: {model}: the host runs {', '.join(KNOWN)}; "
                                    f"without {model} the run would not be the case's (remove it to run without)")
        name = f"{model}Props{i}" if model == "execute" else f"{model}Props"
        props = f.get(name)
        line = entry_line(path, name if props is not None else "liggghtsCommandModels")
        where = f"{path}:{line} {name if props is not None else model}"
        if model == "runLiggghts":
            if props and props.get("runFirst") is True:
                raise CaseCommandsError(f"{where}: runFirst on: CFDEM runs the DEM at the first coupling step "
                                        "only; the host couples it at every step")
            continue
        if model == "writeLiggghts":
            props = props or {}
            if "writeLast" in props:
                raise CaseCommandsError(f"{where}: writeLast: CFDEM's old name, which it refuses: writeLastOnly")
            folder = str(props.get("path", "../DEM")).strip('"')
            name_ = str(props.get("writeName", "liggghts.restartCFDEM")).strip('"')
            overwrite = _switch(props, "overwrite", where) if props else False
            last = _switch(props, "writeLastOnly", where) if "writeLastOnly" in props else False
            every = int(props.get("writeEvery", 1))
            if every < 1:
                raise CaseCommandsError(f"{where}: writeEvery: must be > 0, got {every}")
            found.append(CaseCommand(f"write_restart {folder}/{name_}" + ("" if overwrite else "_"),
                                     stamp=not overwrite, when="last" if last else "write", file=str(path), line=line,
                                     write_every=every))
            continue
        if props is None:
            raise CaseCommandsError(f"{path}: liggghtsCommandModels' execute is number {i} of the list: CFDEM "
                                    f"reads its command from {name}, which the file does not have")
        if "command" not in props:
            raise CaseCommandsError(f"{where}: no command ( ... ) list")
        try:
            text, stamp = compose(props["command"], list(props.get("scalars") or []), list(props.get("labels") or []),
                                  couple_every)
        except StopIteration:
            raise CaseCommandsError(f"{where}: its command asks for more 'number' or 'label' words than "
                                    "scalars ( ... ) or labels ( ... ) give") from None
        if text.split()[:1] in (["run"], ["rerun"]):
            raise CaseCommandsError(f"{where}: '{text.strip()}': steps run outside the coupling, which the host "
                                    "does not follow (its time, contacts and heat); give them to the script")
        why = host_fix_refusal(text.strip())
        if why:
            raise CaseCommandsError(f"{where}: {why}")
        when, times = _when(props, where)
        found.append(CaseCommand(text.rstrip(), stamp=stamp, when=when, file=str(path), line=line, times=times))
    return found


def write_times(control: dict, start: float, t0: float, t1: float) -> int:
    """How many of the fluid's write times (its controlDict ``writeControl`` runTime or
    adjustableRunTime every ``writeInterval`` s, timeStep every ``writeInterval`` steps of
    ``deltaT``, from ``start``) fall in (t0, t1] [s]; CaseCommandsError for a writeControl
    the host cannot follow (clockTime, cpuTime: wall times)."""
    kind = str(control.get("writeControl", "timeStep"))
    if kind in ("runTime", "adjustableRunTime"):
        every = float(control["writeInterval"])
    elif kind == "timeStep":
        every = float(control["writeInterval"]) * float(control["deltaT"])
    else:
        raise CaseCommandsError(f"controlDict writeControl {kind}: the host follows the fluid's write times of "
                                "runTime, adjustableRunTime and timeStep only (writeLiggghts, runEveryWriteStep)")
    tol = 1e-9 * every
    return math.floor((t1 - start + tol) / every) - math.floor((t0 - start + tol) / every)


def couples_to_cfd(commands) -> bool:
    """Whether a LIGGGHTS script (its commands, ``pyhost.engines.liggghts.script.Command``) is a CFDEM one: it
    defines ``fix ID GROUP couple/cfd``. CFDEM runs such a script whole, its last run too
    (often ``run 1``), then its coupling drives the DEM."""
    return any(c.name == "fix" and c.words[3:4] == ["couple/cfd"] for c in commands)
