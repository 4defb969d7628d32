"""The mesh's planes the fluid exchange on the ranks finds a particle's cell by
(``pyhost.engines.fluid_ranks.BoxGrid``): on a graded grid whose cells come in a shuffled
order (a decomposed case's), each point's cell against the cell whose box holds it, found
by brute force; a mesh that is no such grid is refused (the exchange then gathers)."""
import numpy as np

from pyhost.engines.fluid_ranks import BoxGrid


def grid_mesh(rng, shape=(4, 3, 5)):
    """Points and shuffled cell centres of a rectilinear grid with uneven spacing [m]."""
    faces = [np.cumsum(np.r_[0.0, rng.uniform(0.5, 2.0, n)]) * 1e-3 for n in shape]
    points = np.stack(np.meshgrid(*faces, indexing="ij"), axis=-1).reshape(-1, 3)
    mids = [0.5 * (f[1:] + f[:-1]) for f in faces]
    centres = np.stack(np.meshgrid(*mids, indexing="ij"), axis=-1).reshape(-1, 3)
    return faces, points, centres[rng.permutation(len(centres))]


def test_each_point_gets_the_cell_whose_box_holds_it():
    rng = np.random.default_rng(47)
    faces, points, centres = grid_mesh(rng)
    grid = BoxGrid.of(points, centres)
    assert grid is not None and grid.shape == (4, 3, 5)
    lo, hi = points.min(axis=0), points.max(axis=0)
    x = rng.uniform(lo, hi, (2000, 3))
    solver_cell = grid.order[grid.cells(x)]
    half = np.stack([np.diff(f)[np.searchsorted(f, xa) - 1] / 2 for f, xa in zip(faces, x.T)], axis=1)
    assert np.all(np.abs(x - centres[solver_cell]) <= half * (1 + 1e-12))
    # values in the solver's order go to the grid's and back unchanged
    values = rng.normal(size=(len(centres), 3))
    assert np.array_equal(grid.to_solver(grid.to_grid(values)), values)


def test_the_boundary_is_inside_and_beyond_it_is_outside():
    rng = np.random.default_rng(48)
    faces, points, centres = grid_mesh(rng)
    grid = BoxGrid.of(points, centres)
    lo, hi = points.min(axis=0), points.max(axis=0)
    corners = np.array([lo, hi, [lo[0], hi[1], lo[2]]])
    assert np.all(grid.cells(corners) >= 0)
    beyond = np.array([lo - [1e-9, 0, 0], hi + [0, 0, 1e-9], [hi[0], hi[1] + 1e-6, lo[2]]])
    assert np.all(grid.cells(beyond) == -1)


def test_points_of_a_plane_apart_by_rounding_are_one_plane():
    """blockMesh leaves some points of the plane z = 0 at -6e-19 m: still one plane."""
    rng = np.random.default_rng(49)
    faces, points, centres = grid_mesh(rng)
    points = points.copy()
    on_floor = np.flatnonzero(points[:, 2] == 0.0)
    points[on_floor[::2], 2] = -5.78e-19
    grid = BoxGrid.of(points, centres)
    assert grid is not None and grid.shape == (4, 3, 5)


def test_a_mesh_that_is_not_a_grid_is_refused():
    rng = np.random.default_rng(50)
    faces, points, centres = grid_mesh(rng)
    bent = points.copy()
    bent[7, 0] += 1e-4                      # one point off its plane: a plane more, cells not boxes
    assert BoxGrid.of(bent, centres) is None
    assert BoxGrid.of(points, centres[:-1]) is None            # a cell missing
    moved = centres.copy()
    moved[3] += 1e-5                         # a centre off its box's middle (a cell not a box)
    assert BoxGrid.of(points, moved) is None
    twice = centres.copy()
    twice[1] = twice[0]                      # two cells in one box
    assert BoxGrid.of(points, twice) is None
