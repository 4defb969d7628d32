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

    files = [ROOT / "pyhost" / "loop.py", ROOT / "pyhost" / "checkpoint.py", ROOT / "pyhost" / "tables.py",
             *sorted((ROOT / "pyhost" / "effects").glob("*.py"))]
    used = {f.name: sorted(engine_uses(f) - set(MEMBERS)) for f in files}
    assert {k: v for k, v in used.items() if v} == {}
    assert engine_uses(ROOT / "pyhost" / "loop.py") >= {"run", "step", "dt"}   # the scan sees them
    assert engine_uses(ROOT / "pyhost" / "effects" / "balance.py") >= {"atoms", "events", "info"}
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


def total_uses(source: str) -> list[tuple[str, str, int]]:
    """Where ``source`` touches summary.json's totals: (key, how, line) for each subscript store
    or augmented assignment (``totals[k] += n``, ``t["k"] = ...``: how "add"/"set") and each
    ``get``/``setdefault`` call (how "get"/"setdefault") on a totals dict. A totals dict is an
    expression ending in ``totals`` (``self.loop.totals``) or a name bound to one in the module
    (``t = self.loop.totals``, ``loop, totals = self.loop, self.loop.totals``). A key that is
    not a string constant is reported as "?" (it cannot be checked: name it)."""
    tree = ast.parse(source)

    def is_totals(node) -> bool:
        text = ast.unparse(node)
        return text == "totals" or text.endswith(".totals")

    aliases = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign):
            for target in node.targets:
                pairs = (zip(target.elts, node.value.elts) if isinstance(target, ast.Tuple)
                         and isinstance(node.value, ast.Tuple) else [(target, node.value)])
                aliases |= {t.id for t, v in pairs if isinstance(t, ast.Name) and is_totals(v)}

    def of_totals(node) -> bool:
        return is_totals(node) or isinstance(node, ast.Name) and node.id in aliases

    def key(node) -> str:
        return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else "?"

    found = []
    for node in ast.walk(tree):
        targets = (node.targets if isinstance(node, ast.Assign) else [node.target]
                   if isinstance(node, ast.AugAssign) else [])
        for t in targets:
            if isinstance(t, ast.Subscript) and of_totals(t.value):
                found.append((key(t.slice), "add" if isinstance(node, ast.AugAssign) else "set", node.lineno))
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                and node.func.attr in ("get", "setdefault") and of_totals(node.func.value)):
            found.append((key(node.args[0]) if node.args else "?", node.func.attr, node.lineno))
    return found


def test_the_scan_of_totals_finds_each_way_of_adding_one():
    """The scan below sees an undeclared total however it is added to (planted examples)."""
    planted = """
def f(self, loop):
    self.loop.totals["a"] += 1
    t = self.loop.totals
    t["b"] = t.get("b", 0) + 2
    loop.totals.setdefault("c", 0)
    x, totals = 1, loop.totals
    totals[name] += 3
    other["d"] += 1
"""
    assert sorted(total_uses(planted)) == [("?", "add", 8), ("a", "add", 3), ("b", "get", 5), ("b", "set", 5),
                                           ("c", "setdefault", 6)]


def test_each_total_is_declared_once_by_the_effect_that_adds_to_it():
    """summary.json's totals: each effect's ``TOTALS`` (no key in two effects: they would add
    to one number without knowing), all of them in ``pyhost.effects.totals()``, and every total
    any module of pyhost adds to or sets declared (else the run's first addition is a KeyError,
    or a summary has the key only when it is not 0), by a string constant; none taken with
    ``get`` or ``setdefault`` (a declared total is always there: they could only hide one that
    is not)."""
    import importlib

    from pyhost.effects import REGISTRY, Effect, effect_class, totals

    for f in sorted((ROOT / "pyhost" / "effects").glob("*.py")):     # every effect module, imported
        importlib.import_module(f"pyhost.effects.{f.stem}" if f.stem != "__init__" else "pyhost.effects")
    effects = [e for e in Effect.__subclasses__() if e.TOTALS]
    assert len(effects) >= 4
    assert set(effects) <= {effect_class(name) for name, _, _ in REGISTRY}     # (every one registered)
    declared = [k for effect in effects for k in effect.TOTALS]
    assert len(declared) == len(set(declared)), sorted(k for k in declared if declared.count(k) > 1)
    assert sorted(totals()) == sorted(declared) and not any(totals().values())
    uses = {(f"{f.relative_to(ROOT)}:{line}", k, how) for f in sorted((ROOT / "pyhost").rglob("*.py"))
            for k, how, line in total_uses(f.read_text())}
    assert len([u for u in uses if u[2] == "add"]) >= 15                  # (the scan finds the effects' additions)
    assert sorted(u for u in uses if u[1] not in declared or u[2] in ("get", "setdefault")) == []
    # and none around the declaration written in any other way (the regex of the figures' tool)
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

    files = [ROOT / "pyhost" / "loop.py", ROOT / "pyhost" / "checkpoint.py", ROOT / "pyhost" / "run_scene.py", ROOT / "pyhost" / "tables.py",
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


def test_the_loop_only_schedules():
    """Issue 45: pyhost/loop.py holds at most 200 lines and names no effect (neither the class
    nor the module of any effect of the registry): the effects are built from
    ``pyhost.effects.REGISTRY`` and found by the name it gives them."""
    from pyhost.effects import REGISTRY, effect_class

    text = (ROOT / "pyhost" / "loop.py").read_text()
    assert len(text.splitlines()) <= 200
    names = {effect_class(name).__name__ for name, _, _ in REGISTRY}
    modules = {f"effects.{where.split(':')[0]}" for _, _, where in REGISTRY}
    assert len(names) == len(REGISTRY) >= 6 and "EnergyBalance" in names
    named = sorted(n for n in names | modules if re.search(rf"\b{re.escape(n)}\b", text))
    named += sorted(f'find("{name}")' for name, _, _ in REGISTRY if f'find("{name}")' in text)
    assert named == []


def context_reads(path) -> set:
    """The attributes an effect module reads of its context: ``self.loop.X`` and ``loop.X``."""
    found = set()
    for node in ast.walk(ast.parse(Path(path).read_text())):
        if isinstance(node, ast.Attribute):
            v = node.value
            if (isinstance(v, ast.Name) and v.id == "loop" or isinstance(v, ast.Attribute) and v.attr == "loop"
                    and isinstance(v.value, ast.Name) and v.value.id == "self"):
                found.add(node.attr)
    return found


def test_the_effects_read_only_their_declared_context():
    """Issue 45: an effect reads of the run only what ``pyhost.effects.Context.READS`` declares
    (no attribute of the loop, no other effect but through ``find``), and the context has each."""
    from pyhost.effects import Context

    assert context_reads(ROOT / "pyhost" / "effects" / "balance.py") >= {"dem", "totals"}   # the scan sees them
    used = {f.name: sorted(context_reads(f) - set(Context.READS))
            for f in sorted((ROOT / "pyhost" / "effects").glob("*.py")) if f.name != "__init__.py"}
    assert {k: v for k, v in used.items() if v} == {}
    fields = set(Context.__dataclass_fields__)
    set_later = {"effects", "heat", "capacity", "type_material"}        # (__post_init__'s)
    assert [r for r in Context.READS if r not in fields | set_later and not hasattr(Context, r)] == []
    assert not any(r.startswith("_") for r in Context.READS)
