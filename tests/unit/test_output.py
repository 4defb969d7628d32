"""Output survives as it is written: CSV rows flushed, VTK series readable mid-run."""
import csv
import io
import os
import json

import meshio
import numpy as np
import pytest
import pyvista

from pyhost.effects.collisions import COLLISION_COLUMNS
from pyhost.output import (ColumnLog, CsvLog, PieceSeries, Progress, VtkSeries, collision_kinds, collisions_to_csv,
                           read_collisions, read_columns, wait_piece, write_piece)


def test_csv_rows_are_on_disk_before_close(tmp_path):
    """Rows go to disk by the output thread: once the log's size is asked (a checkpoint's mark),
    they are there, flushed, before the log is closed."""
    log = CsvLog(tmp_path / "c.csv", ("time", "i", "Q"))
    log.write_columns(time=np.array([0.1, 0.2]), i=np.array([3, 4]), Q=np.array([1e-6, 2e-6]))
    assert log.size == (tmp_path / "c.csv").stat().st_size
    text = (tmp_path / "c.csv").read_text().splitlines()      # not closed yet
    assert text == ["time,i,Q", "0.1,3,1e-06", "0.2,4,2e-06"]
    log.close()


def test_csv_columns_are_the_bytes_csv_writer_writes(tmp_path):
    """Columns are formatted without csv.writer where no value needs quotes (output._csv_lines):
    the file is byte for byte what csv.writer writes from the same rows, with floats at every
    digit, signed zeros, NaN and infinities, integers and text, and text that needs quotes."""
    rng = np.random.default_rng(3)
    n = CsvLog.CHUNK + 11
    x = rng.normal(0.0, 1.0, n) * 10.0 ** rng.integers(-300, 300, n)
    x[:4] = [-0.0, np.nan, np.inf, 1e-7]
    cols = dict(t=x, step=rng.integers(-2**62, 2**62, n), model=np.where(rng.random(n) < 0.5, "A", "exact B"),
                small=rng.normal(0.0, 1.0, n).astype(np.float32))
    quoted = dict(cols, model=np.where(rng.random(n) < 0.5, "A", 'say "B", \r\nthen C'))
    for name, columns in (("plain", cols), ("quoted", quoted)):
        log = CsvLog(tmp_path / f"{name}.csv", tuple(columns))
        log.write_columns(**columns)
        log.close()
        expected = io.StringIO(newline="")
        writer = csv.writer(expected)
        writer.writerow(tuple(columns))
        writer.writerows(zip(*(c.tolist() for c in columns.values())))
        assert (tmp_path / f"{name}.csv").read_bytes() == expected.getvalue().encode()


def test_csv_rows_are_written_from_copies_in_order(tmp_path):
    """The output thread writes the columns as they were when given, in the order given, in
    chunks of CHUNK rows: the caller may change its arrays at once (the next batch)."""
    log = CsvLog(tmp_path / "c.csv", ("i", "Q"))
    n = 2 * CsvLog.CHUNK + 7
    ids, Q = np.arange(n), np.linspace(0.0, 1.0, n)
    log.write_columns(i=ids, Q=Q)
    ids[:] = -1
    Q[:] = np.nan
    log.write([(n, 2.0)])
    log.close()
    rows = (tmp_path / "c.csv").read_text().splitlines()[1:]
    assert rows == [f"{k},{q!r}" for k, q in zip(range(n), np.linspace(0.0, 1.0, n).tolist())] + [f"{n},2.0"]


def test_vtk_series_readable_after_each_frame(tmp_path):
    series = VtkSeries(tmp_path, "particles")
    rng = np.random.default_rng(0)
    for k in range(2):
        x = rng.uniform(size=(7, 3))
        series.write(0.1 * k, x, id=np.arange(7), temperature=np.full(7, 300.0 + k))
        series.flush()
        reader = pyvista.get_reader(str(tmp_path / "particles.pvd"))
        assert reader.time_values == pytest.approx([0.1 * j for j in range(k + 1)])
        reader.set_active_time_value(0.1 * k)
        mesh = reader.read()[0]
        assert mesh.n_points == 7
        assert np.allclose(mesh.points, x) and np.all(mesh.point_data["temperature"] == 300.0 + k)


def test_frames_in_pieces_read_back_whole_and_a_restart_keeps_only_its_frames(tmp_path):
    """A frame written in pieces (one .vtu per MPI rank, here both written by this process as
    ranks 0 and 1 would) reads back through its .pvtu, and the .pvd lists the .pvtu files, as
    one mesh: the pieces' points in rank order, every array as written (dtype included); the
    dumps reader reads the .pvtu too. A restart from a checkpoint after the first frame (here on
    one rank) removes the later frame's .pvtu and pieces and keeps the first's."""
    from pyhost.dumps import DumpReader

    rng = np.random.default_rng(1)
    series = PieceSeries(tmp_path, "particles", 2)
    written = []
    for k in range(2):
        parts = [dict(x=rng.uniform(size=(n, 3)), id=np.arange(n) + 10 * r + 1, type=np.full(n, 1, np.int32),
                      radius=np.full(n, 1e-3), v=rng.normal(size=(n, 3))) for r, n in enumerate((5, 3 + k))]
        for r, p in enumerate(parts):
            write_piece(tmp_path, "particles", series.next_frame(), r, p["x"], id=p["id"], type=p["type"],
                        radius=p["radius"], v=p["v"])
        wait_piece(tmp_path, "particles")
        series.add(0.1 * k, {name: parts[0][name][:0] for name in ("id", "type", "radius", "v")})
        written.append(parts)
    series.flush()
    reader = pyvista.get_reader(str(tmp_path / "particles.pvd"))
    assert reader.time_values == pytest.approx([0.0, 0.1])
    for k, parts in enumerate(written):
        mesh = pyvista.read(str(tmp_path / f"particles_{k:05d}.pvtu"))
        assert np.array_equal(mesh.points, np.concatenate([p["x"] for p in parts]))
        for name in ("id", "type", "radius", "v"):
            whole = np.concatenate([p[name] for p in parts])
            assert mesh[name].dtype == whole.dtype and np.array_equal(mesh[name], whole), name
    frame = next(iter(DumpReader([tmp_path / "particles_00001.pvtu"])))
    assert np.array_equal(frame["id"], np.concatenate([p["id"] for p in written[1]]))
    VtkSeries(tmp_path, "particles", frames=[(0.0, "particles_00000.pvtu")])        # (continued on one rank)
    assert sorted(p.name for p in tmp_path.glob("particles_*")) == [
        "particles_00000.pvtu", "particles_00000_p0.vtu", "particles_00000_p1.vtu"]
    assert pyvista.get_reader(str(tmp_path / "particles.pvd")).time_values == pytest.approx([0.0])


def test_progress_line():
    out = io.StringIO()
    p = Progress(end=2.0, every=0.0, stream=out)
    p.update(0.5, ", 12 collisions")
    line = out.getvalue()
    assert "t = 0.5 / 2 s ( 25.0 %)" in line and "12 collisions" in line


def _rows(rng, n, model):
    return dict(time=rng.uniform(0, 1, n), i=rng.integers(1, 1 << 30, n), j=rng.integers(0, 9, n),
                wall=rng.integers(0, 3, n), v0=rng.lognormal(0, 3, n), Q=rng.normal(0, 1e-5, n),
                e=np.where(rng.uniform(size=n) < 0.1, np.nan, rng.uniform(size=n)), t_coll=rng.uniform(0, 1e-5, n),
                model=np.full(n, model), Q_softened=rng.normal(0, 1e-3, n))


def test_binary_collision_log_reads_back_as_its_csv_form_bit_for_bit(tmp_path):
    """The same rows through CsvLog and ColumnLog (a second text value appearing in a later
    write): read_collisions gives equal arrays from both, bit for bit (NaN included), and the
    converter's CSV is the directly written file byte for byte."""
    rng = np.random.default_rng(1)
    columns = ("time", "i", "j", "wall", "v0", "Q", "e", "t_coll", "model", "Q_softened")
    (tmp_path / "csv").mkdir()
    direct = CsvLog(tmp_path / "csv" / "collisions.csv", columns)
    binary = ColumnLog(tmp_path / "bin" / "collisions", collision_kinds(columns))
    for n, model in ((5, "A"), (0, "A"), (300, "B")):
        rows = _rows(rng, n, model)
        direct.write_columns(**rows)
        binary.write_columns(**rows)
    direct.close()
    binary.close()
    a, b = read_collisions(tmp_path / "csv"), read_collisions(tmp_path / "bin")
    assert list(a) == list(b) == list(columns) and len(a["i"]) == 305
    for c in columns:
        if c == "model":
            assert a[c].tolist() == b[c].tolist() == ["A"] * 5 + ["B"] * 300
        else:
            assert a[c].dtype == b[c].dtype and a[c].tobytes() == b[c].tobytes(), c
    converted = collisions_to_csv(tmp_path / "bin")
    assert converted.read_bytes() == (tmp_path / "csv" / "collisions.csv").read_bytes()


def test_column_log_resumes_at_a_row_count_and_refuses_ragged_columns(tmp_path):
    """resume_at (rows at a checkpoint) cuts every column file there, rows follow; a column
    file one value short is reported by name."""
    kinds = dict(t="f8", k="i8", m="str")
    log = ColumnLog(tmp_path / "c", kinds)
    log.write_columns(t=np.array([0.5, 1.5]), k=np.array([1, 2]), m=np.array(["x", "y"]))
    at = log.size
    log.write_columns(t=np.array([2.5]), k=np.array([3]), m=np.array(["z"]))
    log.close()
    log = ColumnLog(tmp_path / "c", kinds, resume_at=at)
    log.write_columns(t=np.array([9.0]), k=np.array([9]), m=np.array(["y"]))
    log.close()
    got = read_columns(tmp_path / "c")
    assert got["t"].tolist() == [0.5, 1.5, 9.0] and got["k"].tolist() == [1, 2, 9]
    assert got["m"].tolist() == ["x", "y", "y"]
    with open(tmp_path / "c" / "k.i8", "r+b") as f:
        f.truncate(16)
    with pytest.raises(ValueError, match="k.i8: 2 rows"):
        read_columns(tmp_path / "c")


def test_vtk_index_is_rewritten_on_a_clock_and_whole_at_flush(tmp_path, monkeypatch):
    """The .pvd index lists every frame once the series is closed; in between it is rewritten
    at most every INDEX_EVERY seconds (after each frame, 50,000 frames cost quadratic time)."""
    from pyhost.output import VtkSeries

    monkeypatch.setattr(VtkSeries, "INDEX_EVERY", 1e9)
    series = VtkSeries(tmp_path, "p")
    for k in range(3):
        series.write(0.1 * k, np.zeros((2, 3)), id=np.arange(2))
    index = tmp_path / "p.pvd"
    assert index.read_text().count("<DataSet") == 1          # the first frame's, then the clock holds
    series.flush()
    assert index.read_text().count("<DataSet") == 3


@pytest.mark.parametrize("damage, message", [
    (lambda cols: cols[0].update(kind="f4"), r"columns\[0\] \(t\): unknown kind 'f4'; known: f8, i8, str"),
    (lambda cols: cols[1].pop("file"), r"columns\[1\]: needs name, kind and file"),
    (lambda cols: cols[1].update(file="gone.i8"), r"gone.i8: missing \(column k of"),
])
def test_a_damaged_schema_names_the_column(tmp_path, damage, message):
    """A binary log whose schema lost a key or names an unknown kind or file: ValueError
    naming the schema and the column (it was a KeyError, exit 1)."""
    log = ColumnLog(tmp_path / "c", {"t": "f8", "k": "i8"})
    log.write_columns(t=np.array([0.5]), k=np.array([1]))
    log.close()
    path = tmp_path / "c" / "schema.json"
    schema = json.loads(path.read_text())
    damage(schema["columns"])
    path.write_text(json.dumps(schema))
    with pytest.raises(ValueError, match=message):
        read_columns(tmp_path / "c")


@pytest.mark.parametrize("damage, message", [
    (lambda lines: lines.insert(2, "0.5,1,2"), r"collisions.csv: line 3: 3 fields, the header has 10"),
    (lambda lines: lines.__setitem__(1, lines[1].replace("0.25", "x.25", 1)), r"line 2, column time: 'x.25' is not"),
])
def test_a_damaged_collision_log_names_file_and_line(tmp_path, damage, message):
    """A collisions.csv cut or edited by hand: ValueError naming the file, the line and the
    column (it was numpy's message, with neither)."""
    log = CsvLog(tmp_path / "collisions.csv", COLLISION_COLUMNS)
    log.write([(0.25, 25000, 1, 2, 0, 0.1, 1e-6, 0.8, 1e-5, "A"), (0.5, 50000, 2, 3, 0, 0.2, 2e-6, 0.7, 1e-5, "A")])
    log.close()
    lines = (tmp_path / "collisions.csv").read_text().splitlines()
    damage(lines)
    (tmp_path / "collisions.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=message):
        read_collisions(tmp_path)


def test_a_full_disk_names_the_log_it_was_writing(tmp_path):
    """A write that fails (ENOSPC, as from a full disk) names the file: the command line then
    says 'collisions.csv: No space left on device', not 'a file: ...'."""
    import errno

    from pyhost.exitcodes import classify

    class Full:
        def write(self, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        def flush(self):
            pass

        def close(self):
            pass

    log = CsvLog(tmp_path / "collisions.csv", ("time", "i"))
    log._file.close()
    log._file = Full()
    log._csv = csv.writer(log._file)
    log.write([(0.5, 1)])                       # written by the output thread: its error comes
    with pytest.raises(OSError) as err:         # with the next call that waits for it
        log.close()
    code, message = classify(err.value)
    assert code == 2 and message == f"{tmp_path / 'collisions.csv'}: No space left on device"


def test_frames_are_written_from_copies_while_the_caller_goes_on(tmp_path):
    """A frame is written by a thread of its own: it holds the arrays as they were when given
    (the caller's may be the engine's memory, changed by the next chunk)."""
    series = VtkSeries(tmp_path, "p")
    x = np.zeros((3, 3))
    T = np.array([300.0, 310.0, 320.0])
    series.write(0.0, x, temperature=T)
    x += 1.0
    T[:] = 0.0                                  # the engine's next chunk, while the frame is written
    series.flush()
    frame = meshio.read(tmp_path / "p_00000.vtu")
    assert np.array_equal(frame.points, np.zeros((3, 3)))
    assert np.array_equal(frame.point_data["temperature"], [300.0, 310.0, 320.0])


def test_a_frame_that_cannot_be_written_fails_the_next_call(tmp_path):
    """An error while a frame is written (here: its folder gone) is raised in the caller by
    the index that follows (this write's own, the next write's or flush), not lost in the
    writer's thread."""
    series = VtkSeries(tmp_path / "vtk", "p")
    (tmp_path / "vtk").rmdir()
    with pytest.raises(FileNotFoundError, match="p_00000.vtu"):
        series.write(0.0, np.zeros((1, 3)), temperature=np.ones(1))
        series.flush()


def test_a_stop_as_the_writer_thread_starts_leaves_it_joinable(monkeypatch):
    """A signal that lands right after the output writer's thread starts (the first VTK frame:
    test_interrupts' SIGINT at the first history row) used to raise inside the thread pool's
    submit, before the pool registered the thread for the interpreter's exit: the thread then
    waited for work forever and the process, having said it stopped cleanly, never exited (a
    CI run timed out after 60 s; py-spy showed the main thread in threading._shutdown). The
    thread now starts with stops deferred: the stop is raised after, and the thread is
    registered."""
    import concurrent.futures.thread as pool
    import os
    import signal
    import threading

    from pyhost import output, signals

    start = threading.Thread.start

    def start_then_signal(self):
        start(self)
        if self.name.startswith("output-writer"):
            os.kill(os.getpid(), signal.SIGINT)

    before = set(threading.enumerate())            # (earlier tests' writer stays theirs)
    monkeypatch.setattr(output, "_writer", None)
    monkeypatch.setattr(threading.Thread, "start", start_then_signal)
    with signals.stopping(), pytest.raises(signals.Interrupted):
        output._output_writer().submit(int).result()        # as VtkSeries and CsvLog hand it work
    writers = [t for t in set(threading.enumerate()) - before if t.name.startswith("output-writer")]
    try:
        assert writers and all(t in pool._threads_queues for t in writers)
    finally:                          # ended here: an orphaned thread would keep pytest from exiting
        if output._writer is not None:
            output._writer.shutdown()
        for t in writers:
            t.join(timeout=10)


def test_a_stop_during_a_checkpoint_leaves_no_half_checkpoint(tmp_path):
    """A signal that stops the run while a checkpoint is written (here, as LIGGGHTS writes its
    restart) left OUT/.checkpoint.new beside the last good checkpoint; it is removed, and the
    last checkpoint stays as it was."""
    import signal
    from types import SimpleNamespace

    from pyhost import checkpoint
    from pyhost.signals import Interrupted

    (tmp_path / "checkpoint").mkdir()
    (tmp_path / "checkpoint" / "manifest.json").write_text("{}")

    def stopped(path):
        (tmp_path / ".checkpoint.new" / "dem.restart").write_bytes(b"half")
        raise Interrupted(signal.SIGTERM)
    dem = SimpleNamespace(per_atom=lambda names: (np.arange(2.0), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))),
                          write_restart=stopped, info=SimpleNamespace(streams=[]),
                          box=lambda: (-np.ones(3), np.ones(3), np.zeros(3, bool)))
    with pytest.raises(Interrupted):
        checkpoint.write(SimpleNamespace(out=tmp_path, dem=dem, scene=None))
    assert not (tmp_path / ".checkpoint.new").exists()
    assert (tmp_path / "checkpoint" / "manifest.json").read_text() == "{}"
