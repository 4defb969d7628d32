"""The dump reader: dumps written by the real LIGGGHTS (marked engines) and hand-made bad files."""
import gzip
import shutil
import tracemalloc

import numpy as np
import pytest

from pyhost.dumps import DumpError, DumpReader
from pyhost.engines.liggghts.computes import Compute, parse_compute
from pyhost.engines.liggghts.dump_script import read_script, setup_variables

ALL = ("id", "type", "position", "velocity", "radius")
STEPS = list(range(0, 6001, 500))


def by_id(frame):
    order = np.argsort(frame["id"])
    return frame["id"][order], frame.positions()[order], frame.vector("v")[order], frame["radius"][order]


@pytest.mark.engines
def test_one_file_per_step_many_steps_in_one_file_vtk_and_gzip_agree(pour_dumps):
    post = pour_dumps / "post"
    for f in post.glob("dump.*"):
        with open(f, "rb") as src, gzip.open(post / f"gz.{f.name}.gz", "wb") as dst:
            shutil.copyfileobj(src, dst)
    per_step = list(DumpReader([post / "dump.*"], dt=1e-5, require=ALL))
    single = list(DumpReader([post / "all.dump"], require=ALL))
    vtk = list(DumpReader([post / "p_*.vtk"], require=ALL))
    gz = list(DumpReader([post / "gz.*"], require=ALL))
    assert [f.step for f in per_step] == STEPS                    # numeric order, not by name
    assert [f.time for f in per_step] == pytest.approx([s * 1e-5 for s in STEPS], rel=1e-12)
    for frames in (single, vtk, gz):
        assert [f.step for f in frames] == STEPS
    assert len(per_step[0]) == 0 and len(per_step[-1]) == 60      # before insertion; nparticles 60
    for a, b, c, d in zip(per_step, single, vtk, gz):
        ia, xa, va, ra = by_id(a)
        for other, tol in ((b, 0.0), (d, 0.0), (c, 5e-6)):        # %g keeps 6 digits, the VTK more
            ib, xb, vb, rb = by_id(other)
            assert np.array_equal(ia, ib) and np.array_equal(ra, rb)
            assert np.allclose(xa, xb, rtol=tol, atol=tol * 1e-6) and np.allclose(va, vb, rtol=tol, atol=tol * 1e-2)
        assert a.periodic == (True, True, False) and b.periodic == (True, True, False)
        assert np.array_equal(a.box, [[-0.01, 0.01], [-0.01, 0.01], [-0.001, 0.03]])
        assert np.all(a["f_Temp"] == 300.0) and np.all(b["f_Temp[0]"] == 300.0)   # both spellings
        # the script's two templates: type 1 has radius 1 mm, type 2 1.5 mm
        assert np.all(np.where(a["type"] == 1, 1e-3, 1.5e-3) == a["radius"])


@pytest.mark.engines
def test_contact_columns_follow_liggghts_code_order_not_typed_order(pour_dumps):
    """Overlaps written by LIGGGHTS agree with the positions in the same rows, which holds only
    if every column is placed where LIGGGHTS wrote it (the script types 'delta id vel pos')."""
    script = read_script(pour_dumps / "in.pour")
    assert script.timestep == 1e-5 and script.mesh_wall_fixes == ("walls",)
    radius = {}
    for f in DumpReader([pour_dumps / "post" / "dump.*"]):
        radius.update(zip(f["id"].astype(int), f["radius"]))
    rows = {"pair": 0, "wall": 0}
    frames = lambda name: DumpReader([pour_dumps / "post" / name], computes=script.computes)
    for f in (*frames("pair.*"), *frames("wall.*")):
        if not len(f):
            continue
        rows[f.kind] += len(f)
        r_i = np.array([radius[i] for i in f["id_i"].astype(int)])
        if f.kind == "pair":
            r_j = np.array([radius[j] for j in f["id_j"].astype(int)])
            d = f.vector("x_i") - f.vector("x_j")
            d[:, :2] -= 0.02 * np.round(d[:, :2] / 0.02)               # periodic in x and y
            expected = r_i + r_j - np.linalg.norm(d, axis=1)
            assert set(np.unique(f["periodic"])) <= {0.0, 1.0}
        else:
            expected = r_i - f.vector("x_i")[:, 2]                     # the STL floor is z = 0
            assert np.all(f.vector("x_contact")[:, 2] == 0.0) and np.all(f["mesh"] == 0)
            assert np.all(f.vector("v_wall") == 0.0)
        # %g keeps 6 digits of centres ~1e-2 m: 1e-7 m on an overlap
        assert np.allclose(f["delta"], expected, rtol=0, atol=1e-7), (f.file, f["delta"], expected)
    assert rows["pair"] > 50 and rows["wall"] > 50


def test_layout_of_liggghts_3_8():
    """ENGINES.md: 'pos vel id force delta heatFlux' gives id_i 13, periodic 15, overlap 19, heat 20."""
    cols = Compute("c", "pair/gran/local", ("heatFlux", "delta", "force", "id", "vel", "pos")).columns()
    assert len(cols) == 20
    assert cols[12] == ("id_i", None) and cols[14] == ("periodic", None)
    assert cols[15:18] == [("force", 0), ("force", 1), ("force", 2)]
    assert cols[18] == ("delta", None) and cols[19] == ("heat_flux", None)
    wall = Compute("w", "wall/gran/local", ("delta", "force", "id", "vel", "pos")).columns()
    assert wall[12:15] == [("mesh", None), ("triangle", None), ("id_i", None)] and wall[18] == ("delta", None)
    assert parse_compute("compute c all pair/gran/local pos verbose extraSurfDistance 1e-3 # note") \
        == Compute("c", "pair/gran/local", ("pos",))
    with pytest.raises(ValueError, match="keyword 'speed'"):
        parse_compute("c pair/gran/local pos speed")


def local_dump(columns, rows, step=10):
    return (f"ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ENTRIES\n{len(rows)}\nITEM: BOX BOUNDS ff ff ff\n"
            "0 1\n0 1\n0 1\n" f"ITEM: ENTRIES {' '.join(columns)} \n" + "".join(f"{r}\n" for r in rows))


@pytest.mark.parametrize("keywords, column, problem", [
    ((), "c_c[25]", "history"),                       # default keywords: 'history' of unknown width first
    (("pos", "id"), "c_c[10]", "writes 9 columns, not 10"),
])
def test_a_column_that_cannot_be_placed_is_an_error(tmp_path, keywords, column, problem):
    (tmp_path / "l").write_text(local_dump([column], ["1"]))
    with pytest.raises(DumpError, match=problem) as err:
        list(DumpReader([tmp_path / "l"], computes={"c": Compute("c", "pair/gran/local", keywords)}))
    assert err.value.line == 9 and err.value.step == 10
    with pytest.raises(DumpError, match="needs its keywords"):
        list(DumpReader([tmp_path / "l"]))


HEAD = "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ATOMS\n{n}\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 2\n"
COLUMNS = "ITEM: ATOMS id type x y z vx vy vz radius \n"


def atoms(step=100, rows=None):
    rows = rows or [f"{k} 1 0.{k} 0.5 0.5 0 0 -1 0.01" for k in (3, 1, 2)]
    return HEAD.format(step=step, n=len(rows)) + COLUMNS + "".join(r + "\n" for r in rows)


def with_row(k, text):
    rows = [f"{j} 1 0.{j} 0.5 0.5 0 0 -1 0.01" for j in (3, 1, 2)]
    rows[k] = text
    return atoms(rows=rows)


GOOD = atoms()
# name -> (file content or bytes, problem, timestep, line); row k of a frame at line 10 + k
CATALOGUE = {
    "truncated file": (GOOD[: GOOD.rindex("2 1")], "file ends after 2 rows of 3", 100, 12),
    "truncated gzip": (gzip.compress((GOOD * 400).encode())[:-200], "truncated or corrupt stream", None, None),
    "missing header": (GOOD.replace("ITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 2\n", ""), "expected 'ITEM: BOX BOUNDS'",
                       100, 5),
    "malformed header": (GOOD.replace("NUMBER OF ATOMS", "NUMBER ATOMS"), "expected 'ITEM: NUMBER OF ATOMS'", 100, 3),
    "bad box flags": (GOOD.replace("pp pp ff", "pp qq ff"), "box boundary flags", 100, 5),
    "wrong column count": (with_row(1, "1 1 0.1 0.5 0.5 0 0 -1"), "8 values in a row, the header names 9", 100, 11),
    "required column": (GOOD.replace(" radius ", " diameter "), "required column missing: radius", 100, 9),
    "nan": (with_row(2, "2 1 0.2 nan 0.5 0 0 -1 0.01"), "non-finite value 'nan'", 100, 12),
    "inf": (with_row(0, "3 1 0.3 0.5 0.5 0 inf -1 0.01"), "non-finite value 'inf'", 100, 10),
    "negative radius": (with_row(1, "1 1 0.1 0.5 0.5 0 0 -1 -0.01"), "negative radius -0.01", 100, 11),
    "duplicate ids": (with_row(2, "3 1 0.2 0.5 0.5 0 0 -1 0.01"), "duplicate id 3", 100, 12),
    "non-numeric": (with_row(1, "1 1 0.1 0.5 0,5 0 0 -1 0.01"), "non-numeric value '0,5'", 100, 11),
    "empty file": ("", "empty file", None, 0),
    "not a dump": ("atom_style granular\nunits si\n", "not a LIGGGHTS dump", None, 1),
    "short frame then next": (atoms(rows=["1 1 0.1 0.5 0.5 0 0 -1 0.01"]).replace("ATOMS\n1", "ATOMS\n2") + atoms(200),
                              "frame has 1 rows, its header says 2", 100, 11),
}


@pytest.mark.parametrize("name", CATALOGUE)
def test_bad_files_are_refused_naming_file_timestep_and_line(tmp_path, name):
    content, problem, step, line = CATALOGUE[name]
    path = tmp_path / "bad.dump"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(DumpError, match=problem) as err:
        list(DumpReader([path], require=ALL))
    assert err.value.file == str(path) and err.value.step == step
    if line is not None:
        assert err.value.line == line
    else:
        assert err.value.line > 1000                  # somewhere in the cut stream, not at its start


def test_timesteps_going_backwards_across_files(tmp_path):
    (tmp_path / "a").write_text(atoms(0) + atoms(200))
    (tmp_path / "b").write_text(atoms(100))
    with pytest.raises(DumpError, match=r"goes backwards \(previous frame: timestep 200") as err:
        list(DumpReader([tmp_path / "b", tmp_path / "a"]))
    assert err.value.file == str(tmp_path / "b") and err.value.step == 100 and err.value.line == 1


def test_skip_bad_frames_warns_and_goes_on(tmp_path):
    bad = with_row(1, "1 1 0.1 0.5 oops 0 0 -1 0.01")
    short = atoms(300, rows=["1 1 0.1 0.5 0.5 0 0 -1 0.01"]).replace("ATOMS\n1", "ATOMS\n5")
    (tmp_path / "d").write_text(atoms(0) + bad.replace("\n100\n", "\n200\n", 1) + short + atoms(400))
    reader = DumpReader([tmp_path / "d"], require=ALL, skip_bad_frames=True)
    assert [f.step for f in reader] == [0, 400]
    assert len(reader.warnings) == 2
    assert "timestep 200: non-numeric value 'oops'" in reader.warnings[0] and "line 23" in reader.warnings[0]
    assert "timestep 300: frame has 1 rows, its header says 5" in reader.warnings[1]


def test_dump_atom_scaled_coordinates(tmp_path):
    """LAMMPS' dump atom writes xs ys zs in box units: x = lo + xs (hi - lo)."""
    text = ("ITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff mm\n-1 3\n0 2\n10 20\n"
            "ITEM: ATOMS id type xs ys zs\n1 1 0.25 0.5 0\n2 2 1 0 0.5\n")
    (tmp_path / "a").write_text(text)
    [frame] = DumpReader([tmp_path / "a"])
    assert np.array_equal(frame.positions(), [[0.0, 1.0, 10.0], [3.0, 0.0, 15.0]])
    assert frame.periodic == (False, False, False)


def test_memory_stays_per_frame(tmp_path):
    """200 frames of 2000 particles (about 15 MB of text): the reader's peak allocation stays
    below a tenth of the file, because it holds one frame at a time."""
    rng = np.random.default_rng(1)
    path = tmp_path / "big.dump"
    with open(path, "w") as f:
        for step in range(200):
            data = np.column_stack([np.arange(1, 2001), np.ones(2000), rng.random((2000, 6)), np.full(2000, 1e-3)])
            f.write(HEAD.format(step=step, n=2000) + COLUMNS)
            np.savetxt(f, data, fmt="%g")
    tracemalloc.start()
    frames = sum(1 for _ in DumpReader([path], require=ALL))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert frames == 200
    assert peak < path.stat().st_size / 10, (peak, path.stat().st_size)


def test_keywords_that_do_not_match_the_dump_are_an_error(tmp_path):
    """The dump was written by 'pair/gran/local id delta' (ids in columns 1-3); keywords
    'pos id delta' given by --script place the ids in columns 7-9, where this dump has none:
    refused naming the column (they used to be read as positions silently)."""
    rows = ["1 2 0 1e-5 0 0 0 0 0", "3 4 0 2e-5 0 0 0 0 0"]
    cols = [f"c_c[{k}]" for k in range(1, 10)]
    (tmp_path / "l").write_text(local_dump(cols[:4], [r[:r.index(" 0 0 0 0 0")] for r in rows]))
    good = list(DumpReader([tmp_path / "l"], computes={"c": Compute("c", "pair/gran/local", ("id", "delta"))}))
    assert good[0].data[:, 0].tolist() == [1, 3]
    (tmp_path / "l").write_text(local_dump(cols[:9], ["0.1 0.2 0.3 0.4 0.5 0.6 1.5 2 0", "0 0 0 0 0 0 1 2 0"]))
    with pytest.raises(DumpError, match=r"column c_c\[7\] should hold id_i .* holds 1.5"):
        list(DumpReader([tmp_path / "l"], computes={"c": Compute("c", "pair/gran/local", ("pos", "id", "delta"))}))


def test_a_dump_cut_inside_a_keywords_columns_is_an_error(tmp_path):
    """A dump written by 'pair/gran/local vel id contactArea delta' (11 columns) read with the
    keywords 'pos vel id delta' of an edited script (16): its 11 columns would end inside
    v_j and hold no ids; refused, naming the compute and both widths."""
    cols = [f"c_c[{k}]" for k in range(1, 12)]
    (tmp_path / "l").write_text(local_dump(cols, ["0.1 0 0 0 0 0 1 2 0 3e-6 1e-5"]))
    with pytest.raises(DumpError, match=r"columns 1-11 of compute c, which ends inside its 'v_j' .*16 columns"):
        list(DumpReader([tmp_path / "l"], computes={"c": Compute("c", "pair/gran/local", ("pos", "vel", "id", "delta"))}))
    frames = list(DumpReader([tmp_path / "l"], computes={"c": Compute("c", "pair/gran/local",
                                                                      ("vel", "id", "contactArea", "delta"))}))
    assert frames[0].groups["id_i"] == 6 and frames[0].data[0, 6] == 1


def test_script_primitive_walls_are_read_with_their_numbers(tmp_path):
    """post places a script's primitive walls from its own numbers (pyhost.walls): planes and
    cylinders with literal numbers; one given by a variable cannot be placed and is left out."""
    script = tmp_path / "in.walls"
    script.write_text("timestep 1e-5\n"
                      "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n"
                      "fix drum all wall/gran model hertz tangential history primitive type 1 zcylinder 0.05 0. 0.\n"
                      "fix lid all wall/gran model hertz tangential history primitive type 1 zplane ${top}\n"
                      "fix cut all wall/gran model hertz tangential history primitive type 1 xcylinder 0.05\n")
    assert read_script(script).primitives == {"floor": ("zplane", (0.0,)), "drum": ("zcylinder", (0.05, 0.0, 0.0))}


def test_the_scripts_dem_values_give_each_materials_dem_contact(tmp_path):
    """post's DEM contact of each material from the script's fix property/global (per type, the
    restitution per type pair read at (t, t)); the primitive wall's material from its type; a
    value given as a variable cannot be read, and the refusal says so and where."""
    from pyhost.post import Post
    from pyhost.scene import load_post_scene

    material = ("density = 2500.0\nyoungs_modulus = 63e9\npoisson_ratio = 0.22\nyield_stress = 500e6\n"
                "heat_capacity = 800.0\nconductivity = 1.0\n")
    (tmp_path / "scene.toml").write_text(f"[materials.glass]\ntypes = [1]\n{material}[materials.steel]\ntypes = [2]\n"
                                         f"{material}[materials.wood]\n{material}"
                                         '[[walls]]\nfix = "floor"\nmaterial = "wood"\n')
    script = tmp_path / "in.values"
    text = ("timestep 1e-5\n"
            "fix m1 all property/global youngsModulus peratomtype 5e6 2e7 3e7\n"
            "fix m2 all property/global poissonsRatio peratomtype 0.3 0.25 0.2\n"
            "fix m3 all property/global coefficientRestitution peratomtypepair 3 0.8 0.7 0.6 0.7 0.5 0.4 0.6 0.4 0.3\n"
            "fix floor all wall/gran model hertz tangential history primitive type 3 zplane 0.0\n")
    script.write_text(text)
    glass, steel, wood = Post.dem_contacts(load_post_scene(tmp_path / "scene.toml"), read_script(script))
    script.write_text(text + "fix lid all wall/gran model hertz tangential history primitive type 3 zplane 0.1\n")
    post = Post([], load_post_scene(tmp_path / "scene.toml"), tmp_path / "out", script=read_script(script))
    assert any("the script's walls lid have no [[walls]] entry" in w for w in post.warnings)     # floor has one
    script.write_text(text)
    assert (glass.dem.youngs_modulus, glass.dem.poisson_ratio, glass.dem.restitution) == (5e6, 0.3, 0.8)
    assert (steel.dem.youngs_modulus, steel.dem.poisson_ratio, steel.dem.restitution) == (2e7, 0.25, 0.5)
    assert (wood.dem.youngs_modulus, wood.dem.poisson_ratio, wood.dem.restitution) == (3e7, 0.2, 0.3)
    script.write_text(text.replace("peratomtype 5e6 2e7 3e7", "peratomtype ${E} ${E} ${E}"))
    with pytest.raises(ValueError, match=r"sets no youngsModulus .*given as variables: .*in.values: line 2: youngsModulus"):
        Post.dem_contacts(load_post_scene(tmp_path / "scene.toml"), read_script(script))


def test_the_steps_of_a_scripts_temperature_sets(tmp_path):
    """Where a script sets Temp, counted through its runs (plain numbers; 'upto'; reset_timestep;
    a $variable makes the step unknown until a reset), with the line it is on after '&'
    continuations; a set before any run is the first frame's and not listed."""
    script = tmp_path / "in.sets"
    script.write_text("timestep 1e-5\nset group all property/atom Temp 300\nrun 100\n"
                      "set region hot property/atom Temp 800. # half\n"
                      "run 500 upto &\n   post no\nset type 2 property/atom Temp 250\nrun ${n}\n"
                      "set type 1 property/atom Temp 350\nreset_timestep 0\nrun 7\nset atom 3 property/atom Temp 9\n")
    sets = read_script(script).temperature_sets
    assert [(step, where.rsplit(": ", 1)[1]) for step, where, _ in sets] == \
        [(100, "line 4"), (500, "line 7"), (None, "line 9"), (7, "line 12")]
    assert sets[0][2] == "set region hot property/atom Temp 800."


def test_which_variables_posts_set_up_evaluates_as_the_run_does():
    """post's set-up runs a script's variable commands with a box and no particles: numbers,
    the box, math functions and such variables mean there what they mean in the run (after
    Debian's packing tutorial's growth formula); a formula naming the particles (count(all)),
    the run (step) or a compute, an atom-style variable, and whatever names one of them or an
    undefined variable do not, each with the reason; a -var value counts as defined."""
    lines = list(enumerate([
        "variable alphastart equal 0.25", "variable growts equal 50000",
        "variable Rgrowrate equal (0.67/${alphastart})^(40/(3.*${growts}))",
        "variable top equal zhi-0.5*lz+v_growts*1e-9", "variable n index 10 20", "variable label format n %.3f",
        "variable nat equal count(all)", "variable t equal step*dt", "variable d atom 2.*c_rad",
        "variable twice equal 2*${nat}", "variable late equal ${fromcli}+1", "variable gone equal ${nowhere}",
        "region box block 0 ${top} 0 1 0 1"], start=1))
    same, why = setup_variables(lines, {"fromcli": "3"})
    assert same == {"alphastart", "growts", "Rgrowrate", "top", "n", "label", "late", "fromcli"}
    assert why == {"nat": "its formula names all, count", "t": "its formula names dt, step", "d": "it is atom-style",
                   "twice": "it names nat", "gone": "it names nowhere (not defined)"}


def test_an_included_file_is_read_in_its_place(tmp_path):
    """post reads a script as the run does (pyhost.engines.liggghts.script.script_commands): an included file's
    commands in their place, named by their own file and line; before, post warned 'include
    ... not followed' and missed the included property/globals and runs."""
    (tmp_path / "in.materials").write_text("fix m1 all property/global youngsModulus peratomtype 5e6\n"
                                           "run 300\n")
    (tmp_path / "in.main").write_text("timestep 1e-5\ninclude in.materials\nrun 200\n"
                                      "set type 1 property/atom Temp 350\n")
    script = read_script(tmp_path / "in.main")
    assert script.globals == {"youngsModulus": (f"{tmp_path / 'in.materials'}: line 1", ["peratomtype", "5e6"])}
    assert [(step, where) for step, where, _ in script.temperature_sets] == [(500, f"{tmp_path / 'in.main'}: line 4")]
    assert script.warnings == ()


def test_a_processors_rows_go_with_processor_0s_frame(tmp_path):
    """Files of a dump local written per processor ('%'): processor 0's holds the header (its
    own row count, 1), processor 1's 2 bare rows; read as one frame of 3 rows. Processor 1's
    file alone is refused for what it is, naming processor 0's file to give; a processor's
    file beside a processor 0 file of several steps cannot be split into them."""
    cols = [f"c_c[{k}]" for k in range(1, 4)]
    ids = {"c": Compute("c", "pair/gran/local", ("id",))}            # id_i, id_j, periodic
    (tmp_path / "pair.10.0").write_text(local_dump(cols, ["1 2 0"]))
    (tmp_path / "pair.10.1").write_text("3 4 0\n5 6 1\n")
    (tmp_path / "pair.20.0").write_text(local_dump(cols, [], step=20))
    (tmp_path / "pair.20.1").write_text("")
    frames = list(DumpReader(computes=ids, paths=[tmp_path / "pair.*"]))
    assert [f.step for f in frames] == [10, 20] and frames[0].data.tolist() == [[1, 2, 0], [3, 4, 0], [5, 6, 1]]
    assert len(frames[1]) == 0
    with pytest.raises(DumpError, match="another processor's part of a dump local with '%' in its file name: give "
                                        "processor 0's file"):
        list(DumpReader(computes=ids, paths=[tmp_path / "pair.10.1"]))
    (tmp_path / "all.0").write_text(local_dump(cols, ["1 2 0"]) + local_dump(cols, [], step=20))
    (tmp_path / "all.1").write_text("3 4 0\n")
    with pytest.raises(DumpError, match="whose 2 frames it cannot be split into"):
        list(DumpReader(computes=ids, paths=[tmp_path / "all.*"]))
