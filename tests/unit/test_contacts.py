"""Contacts from geometry: overlaps, normals, approach speeds, periodic images, walls."""
import numpy as np
import pytest

from pyhost.collisions import WALL_BASE
from pyhost.contacts import find_contacts

BOX = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)


def test_pair_overlap_normal_and_approach():
    x = np.array([[0.5, 0.5, 0.5], [0.65, 0.5, 0.5], [0.9, 0.9, 0.9]])
    v = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 0, 0]])
    c = find_contacts(x, v, np.full(3, 0.1), BOX)
    assert len(c) == 1 and {c.i[0], c.j[0]} == {0, 1}
    assert c.delta[0] == pytest.approx(0.05)
    assert c.approach[0] == pytest.approx(2.0)
    assert np.allclose(c.normal[0], (x[c.i[0]] - x[c.j[0]]) / 0.15)


def test_periodic_image_is_found():
    x = np.array([[0.02, 0.5, 0.5], [0.97, 0.5, 0.5]])
    c = find_contacts(x, np.zeros((2, 3)), np.full(2, 0.03), BOX, periodic=(True, False, False))
    assert len(c) == 1 and c.delta[0] == pytest.approx(0.01)
    assert np.allclose(np.abs(c.normal[0]), [1, 0, 0])
    assert len(find_contacts(x, np.zeros((2, 3)), np.full(2, 0.03), BOX)) == 0


def test_walls():
    x = np.array([[0.5, 0.5, 0.05], [0.5, 0.5, 0.5], [0.97, 0.5, 0.5]])
    v = np.array([[0, 0, -2.0], [0, 0, 0], [0.5, 0, 0]])
    c = find_contacts(x, v, np.full(3, 0.1), BOX, walls=("zlo", "xhi"))
    rows = sorted(zip(c.i.tolist(), c.j.tolist()))
    assert rows == [(0, WALL_BASE), (2, WALL_BASE + 1)]
    k = list(c.i).index(0)
    assert c.delta[k] == pytest.approx(0.05) and c.approach[k] == pytest.approx(2.0)
    assert np.allclose(c.normal[k], [0, 0, 1])
    k = list(c.i).index(2)
    assert c.approach[k] == pytest.approx(0.5) and np.allclose(c.normal[k], [-1, 0, 0])


def test_agrees_with_brute_force():
    rng = np.random.default_rng(7)
    x = rng.uniform(size=(300, 3))
    r = rng.uniform(0.01, 0.04, 300)
    c = find_contacts(x, np.zeros_like(x), r, BOX)
    d = np.linalg.norm(x[:, None] - x[None], axis=-1)
    overlap = (r[:, None] + r[None] - d > 0) & ~np.eye(300, dtype=bool)
    assert len(c) == overlap.sum() // 2


def test_verlet_list_never_misses_a_contact():
    from pyhost.contacts import ContactFinder
    rng = np.random.default_rng(11)
    x = rng.uniform(size=(200, 3))
    r = np.full(200, 0.03)
    finder = ContactFinder(r, BOX, periodic=(True, True, False), walls=("zlo",))
    for _ in range(60):
        x = x + rng.normal(scale=0.0008, size=x.shape)
        x[:, :2] %= 1.0
        got = finder(x, np.zeros_like(x))
        fresh = find_contacts(x, np.zeros_like(x), r, BOX, periodic=(True, True, False), walls=("zlo",))
        assert sorted(zip(got.i, got.j)) == sorted(zip(fresh.i, fresh.j))
    assert 1 < finder.rebuilds < 60


def test_primitive_plane_on_a_face_equals_the_face_bit_for_bit():
    """A script's primitive plane at a box face (two-sided) and the scene's face (one-sided)
    give the same overlap, normal and approach for every particle inside the box: post
    places the script's planes as primitives, box scenes as faces (pyhost.walls)."""
    rng = np.random.default_rng(3)
    x, v, r = rng.uniform(0.01, 0.99, (400, 3)), rng.normal(size=(400, 3)), rng.uniform(0.01, 0.05, 400)
    for face, primitive in (("zlo", ("zplane", (0.0,))), ("xhi", ("xplane", (1.0,)))):
        a = find_contacts(x, v, r, BOX, walls=(face,))
        b = find_contacts(x, v, r, BOX, walls=(primitive,))
        assert len(a) > 5
        for name in ("i", "j", "delta", "normal", "approach"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), (face, name)


def test_cylinder_wall_inside_and_outside():
    """zcylinder of radius 0.3 m about (0.5, 0.5): a 0.05 m sphere 0.28 m from the axis
    overlaps it by 0.03 m from inside (normal towards the axis); one 0.33 m from the axis by
    0.02 m from outside (normal away from it); one 0.1 m from the axis touches nothing."""
    x = np.array([[0.78, 0.5, 0.5], [0.5, 0.17, 0.2], [0.6, 0.5, 0.5]])
    v = np.array([[2.0, 0, 0], [0, 1.0, 0], [0, 0, 0]])
    c = find_contacts(x, v, np.full(3, 0.05), BOX, walls=(("zcylinder", (0.3, 0.5, 0.5)),))
    assert sorted(c.i.tolist()) == [0, 1] and set(c.j.tolist()) == {WALL_BASE}
    k = list(c.i).index(0)
    assert c.delta[k] == pytest.approx(0.03) and np.allclose(c.normal[k], [-1, 0, 0]) and c.approach[k] == pytest.approx(2.0)
    k = list(c.i).index(1)
    assert c.delta[k] == pytest.approx(0.02) and np.allclose(c.normal[k], [0, -1, 0]) and c.approach[k] == pytest.approx(1.0)
