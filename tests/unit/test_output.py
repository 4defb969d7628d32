"""Output survives as it is written: CSV rows flushed, VTK series readable mid-run."""
import io

import numpy as np
import pytest
import pyvista

from pyhost.output import CsvLog, Progress, VtkSeries


def test_csv_rows_are_on_disk_before_close(tmp_path):
    log = CsvLog(tmp_path / "c.csv", ("time", "i", "Q"))
    log.write_columns(time=np.array([0.1, 0.2]), i=np.array([3, 4]), Q=np.array([1e-6, 2e-6]))
    text = (tmp_path / "c.csv").read_text().splitlines()      # not closed yet
    assert text == ["time,i,Q", "0.1,3,1e-06", "0.2,4,2e-06"]
    log.close()


def test_vtk_series_readable_after_each_frame(tmp_path):
    series = VtkSeries(tmp_path, "particles")
    rng = np.random.default_rng(0)
    for k in range(2):
        x = rng.uniform(size=(7, 3))
        series.write(0.1 * k, x, id=np.arange(7), temperature=np.full(7, 300.0 + k))
        reader = pyvista.get_reader(str(tmp_path / "particles.pvd"))
        assert reader.time_values == pytest.approx([0.1 * j for j in range(k + 1)])
        reader.set_active_time_value(0.1 * k)
        mesh = reader.read()[0]
        assert mesh.n_points == 7
        assert np.allclose(mesh.points, x) and np.all(mesh.point_data["temperature"] == 300.0 + k)


def test_progress_line():
    out = io.StringIO()
    p = Progress(end=2.0, every=0.0, stream=out)
    p.update(0.5, ", 12 collisions")
    line = out.getvalue()
    assert "t = 0.5 / 2 s ( 25.0 %)" in line and "12 collisions" in line
