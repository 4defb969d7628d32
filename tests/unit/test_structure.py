"""The data flows one way (issue 22): plugins/ (the physics) imports nothing of the host,
pyhost/ nothing of tools/ (scripts that import pyhost), and no module of either reaches
itself again through its imports, counting those inside functions."""
import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def modules() -> dict:
    """{dotted name: file} of every module of pyhost/ and plugins/."""
    found = {}
    for package in ("pyhost", "plugins"):
        for f in (ROOT / package).rglob("*.py"):
            parts = f.relative_to(ROOT).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = f
    return found


def imports(f: Path) -> set:
    """Every module name an import statement of the file names (module level or not)."""
    names = set()
    for node in ast.walk(ast.parse(f.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names |= {node.module} | {f"{node.module}.{a.name}" for a in node.names}
        elif isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
    return names


def graph() -> dict:
    mods = modules()
    return {name: {m for m in imports(f) if m in mods and m != name} for name, f in mods.items()}


def cycles(g: dict) -> list:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(g[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop())
                on.discard(comp[-1])
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(g):
        if v not in index:
            visit(v)
    return found


def test_the_finder_sees_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycles():
    g = graph()
    assert len(g) > 80 and g["pyhost.loop"]          # the walk found the tree
    assert cycles(g) == []


def test_plugins_import_nothing_of_the_host_and_the_host_nothing_of_tools():
    mods = modules()
    upward = {name: sorted(m for m in imports(f) if m.split(".")[0] == "pyhost")
              for name, f in mods.items() if name.startswith("plugins")}
    assert {k: v for k, v in upward.items() if v} == {}
    tools = {name: sorted(m for m in imports(f) if m.split(".")[0] == "tools") for name, f in mods.items()}
    assert {k: v for k, v in tools.items() if v} == {}
    assert not [name for name, f in mods.items() if "spec_from_file_location" in f.read_text()]


def engine_uses(f: Path) -> set:
    """Attributes the file takes of the DEM engine: ``X.dem.NAME`` or ``dem.NAME`` (not the
    scene's ``scene.dem`` table)."""
    used = set()
    for node in ast.walk(ast.parse(f.read_text())):
        if not isinstance(node, ast.Attribute):
            continue
        base = node.value
        is_dem = (isinstance(base, ast.Name) and base.id == "dem") or (isinstance(base, ast.Attribute) and base.attr == "dem")
        owner = base.value if isinstance(base, ast.Attribute) else None
        of_scene = isinstance(owner, ast.Name) and owner.id == "scene" or isinstance(owner, ast.Attribute) and owner.attr == "scene"
        if is_dem and not of_scene:
            used.add(node.attr)
    return used


def test_the_loop_and_its_effects_use_only_the_engine_interface_and_dem_has_it_all():
    """A second DEM engine is one file: the loop, its effects and the checkpoints ask nothing
    of the engine outside pyhost.engines.interface, and LIGGGHTS' bridge implements all of it."""
    from pyhost.engines.dem import Dem
    from pyhost.engines.interface import MEMBERS

    files = [ROOT / "pyhost" / "loop.py", ROOT / "pyhost" / "checkpoint.py",
             *sorted((ROOT / "pyhost" / "effects").glob("*.py"))]
    used = {f.name: sorted(engine_uses(f) - set(MEMBERS)) for f in files}
    assert {k: v for k, v in used.items() if v} == {}
    assert engine_uses(ROOT / "pyhost" / "loop.py") >= {"atoms", "run", "step", "dt"}   # the scan sees them
    dem = Dem.__new__(Dem)
    dem.info = dem.events = dem.link = None           # instance attributes, set by __init__
    missing = [m for m in MEMBERS if not hasattr(dem, m) and not hasattr(Dem, m)]
    assert missing == []


def test_the_plugins_python_is_pure_but_for_the_table_cache():
    """plugins/ does no I/O except plugins/heat/table_cache.py (the fast path's tables on
    disk): no other module imports os, io, pathlib, shutil, tempfile or calls open()."""
    io_modules = {"os", "io", "pathlib", "shutil", "tempfile"}
    found = {}
    for name, f in modules().items():
        if not name.startswith("plugins") or name == "plugins.heat.table_cache":
            continue
        tree = ast.parse(f.read_text())
        names = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        names |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
        opens = any(isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == "open"
                    for n in ast.walk(tree))
        if names & io_modules or opens:
            found[name] = sorted(names & io_modules) + (["open()"] if opens else [])
    assert found == {}


def test_each_total_is_declared_once_by_the_effect_that_adds_to_it():
    """summary.json's totals: each effect's ``TOTALS`` (no key in two effects: they would add
    to one number without knowing), all of them in ``pyhost.loop.totals()``, and every total an
    effect adds to with ``+=`` declared (else the run's first such addition is a KeyError), and
    none added to without a declaration (``totals.get(k, 0) + n``: a key a summary has only
    when it is not 0)."""
    import importlib

    from pyhost.effects import Effect
    from pyhost.loop import totals

    for f in sorted((ROOT / "pyhost" / "effects").glob("*.py")):     # every effect module, imported
        importlib.import_module(f"pyhost.effects.{f.stem}" if f.stem != "__init__" else "pyhost.effects")
    effects = [e for e in Effect.__subclasses__() if e.TOTALS]
    assert len(effects) >= 4
    declared = [k for effect in effects for k in effect.TOTALS]
    assert len(declared) == len(set(declared)), sorted(k for k in declared if declared.count(k) > 1)
    assert sorted(totals()) == sorted(declared) and not any(totals().values())
    added = set()
    for f in (ROOT / "pyhost" / "effects").glob("*.py"):
        for node in ast.walk(ast.parse(f.read_text())):
            if (isinstance(node, ast.AugAssign) and isinstance(node.target, ast.Subscript)
                    and isinstance(node.target.slice, ast.Constant) and isinstance(node.target.slice.value, str)
                    and ast.unparse(node.target.value) in ("t", "totals", "self.totals", "loop.totals", "self.loop.totals")):
                added.add((f.name, node.target.slice.value))
    assert len(added) >= 15                     # (the scan finds the effects' additions)
    assert not {k for _, k in added} - set(declared), sorted(added)
    # and none added around the declaration (totals.get(k, 0) + n, setdefault): anywhere in pyhost
    around = [f"{f.relative_to(ROOT)}:{n}" for f in (ROOT / "pyhost").rglob("*.py")
              for n, line in enumerate(f.read_text().splitlines(), 1)
              if re.search(r"totals\.get\(|totals\.setdefault\(", line)]
    assert around == [], around


# -- issue 45: the engine's syntax in its bridge, one collision pipeline, a small post -----------------

ENGINE_WORDS = re.compile(r"\bfix\s+\S+\s+\S+\s+\S|\bunfix\s+\S|pair_style|pair_coeff|create_box|create_atoms|"
                          r"atom_style|atom_modify|read_restart|write_restart|read_data|neigh_modify|wall/gran|"
                          r"heat/gran|property/global|property/atom|mesh/surface|insert/(pack|stream|rate)|"
                          r"particletemplate|particledistribution|nve/sphere|couple/cfd|f_Temp|dump_modify|"
                          r"communicate\s+single|\btimestep\s+[0-9$]|\brun\s+[0-9$]|\bdump\s+\S+\s+\S+\s+(custom|local|atom)")
"""LIGGGHTS' commands as they appear in a script (the figure of ../shared/tools/structure_figures.py)."""


def engine_syntax_lines(f: Path) -> int:
    """String literals of a file (not docstrings) with LIGGGHTS syntax in them."""
    import io
    import tokenize

    toks = [t for t in tokenize.generate_tokens(io.StringIO(f.read_text()).readline)]
    count, seen = 0, []
    for t in toks:
        if t.type == tokenize.STRING:
            docstring = not seen or (seen[-1].type == tokenize.OP and seen[-1].string == ":")
            if not docstring and ENGINE_WORDS.search(t.string):
                count += 1
        if t.type not in (tokenize.NL, tokenize.NEWLINE, tokenize.COMMENT, tokenize.INDENT, tokenize.DEDENT):
            seen.append(t)
    return count


def test_liggghts_syntax_stays_in_its_bridge():
    """At most 20 string literals with LIGGGHTS syntax in pyhost/ outside pyhost/engines/, in at
    most 5 files (112 in 14 files before issue 45); the box world's input alone has dozens."""
    found = {str(f.relative_to(ROOT)): n for f in sorted((ROOT / "pyhost").rglob("*.py"))
             if "engines" not in f.relative_to(ROOT).parts and (n := engine_syntax_lines(f))}
    assert engine_syntax_lines(ROOT / "pyhost" / "engines" / "liggghts" / "box_input.py") > 10   # (the scan sees them)
    assert sum(found.values()) <= 20 and len(found) <= 5, found


def test_post_is_the_pipeline_fed_from_dumps():
    """post.py at most 450 lines (734 before issue 45): the pipeline's pieces (sphere mass, wall
    codes, minimum-image rounding) live in pyhost/collisions.py only, not in post, the run's
    collision effect or the per-rank path."""
    assert len((ROOT / "pyhost" / "post.py").read_text().splitlines()) <= 450
    piece = re.compile(r"4\.?0?\s*/\s*3\.?0?\s*\*\s*(np\.|math\.)pi|WALL_BASE\s*\+|np\.round\(d\s*/")
    assert len(piece.findall((ROOT / "pyhost" / "collisions.py").read_text())) >= 2      # (the scan sees them)
    copies = {f: len(piece.findall((ROOT / f).read_text()))
              for f in ("pyhost/post.py", "pyhost/effects/collisions.py", "pyhost/effects/rank_heat.py",
                        "pyhost/contacts.py", "pyhost/engines/dem.py", "pyhost/engines/liggghts/box_input.py")}
    assert {f: n for f, n in copies.items() if n} == {}
    assert "heat_path" in (ROOT / "pyhost" / "post.py").read_text()      # post takes any heat path, not "fast" alone


def uses_of(f: Path, holder: str) -> set:
    """Attributes the file takes of the engine's ``holder`` (``events`` or ``info``): ``X.dem.holder.NAME``
    or ``dem.holder.NAME``."""
    used = set()
    for node in ast.walk(ast.parse(f.read_text())):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute) and node.value.attr == holder:
            base = node.value.value
            if isinstance(base, ast.Name) and base.id == "dem" or isinstance(base, ast.Attribute) and base.attr == "dem":
                used.add(node.attr)
    return used


def test_the_engines_events_and_info_are_protocols_of_what_the_host_uses():
    """The loop, its effects and the checkpoints use of ``dem.events`` and ``dem.info`` only
    what pyhost.engines.interface declares (ContactEvents, ScriptInfo), and LIGGGHTS' bridge
    has all of it (the recorder serially and under MPI, the script's info)."""
    from pyhost.engines.events import ContactEvents, RankEvents
    from pyhost.engines.interface import EVENT_MEMBERS, INFO_MEMBERS
    from pyhost.engines.liggghts.script import ScriptInfo

    files = [ROOT / "pyhost" / "loop.py", ROOT / "pyhost" / "checkpoint.py",
             *sorted((ROOT / "pyhost" / "effects").glob("*.py"))]
    events = set().union(*(uses_of(f, "events") for f in files))
    info = set().union(*(uses_of(f, "info") for f in files))
    assert {"take", "window", "restitution"} <= events and "heat_gran" in info       # (the scan sees them)
    assert sorted(events - set(EVENT_MEMBERS)) == [] and sorted(info - set(INFO_MEMBERS)) == []
    assert len(EVENT_MEMBERS) == 9
    for cls in (ContactEvents, RankEvents):
        source = ast.unparse(ast.parse(Path(sys.modules[cls.__module__].__file__).read_text()))
        missing = [m for m in EVENT_MEMBERS if not hasattr(cls, m) and f"self.{m}" not in source]
        assert missing == [], (cls.__name__, missing)
    script_info = ScriptInfo()
    assert [m for m in INFO_MEMBERS if not hasattr(script_info, m)] == []
