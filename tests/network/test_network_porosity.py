"""Exact porosity of a region: sphere-box and sphere-cylinder volumes against closed forms."""

import numpy as np
import pytest

from network import Packing, random_packing
from network.pores import Region, region_porosity
from network.core._porosity import circle_lens_area, disk_rectangle_area, sphere_region_volume

V1 = 4.0 / 3.0 * np.pi


@pytest.mark.parametrize("center, fraction", [
    ((0.0, 0.0, 0.0), 1 / 8),        # a box corner
    ((0.0, 0.0, 1.5), 1 / 4),        # an edge
    ((1.5, 1.5, 0.0), 1 / 2),        # a face
    ((1.5, 1.5, 1.5), 1.0),          # inside
    ((-1.0, 1.5, 1.5), 0.0),         # touching from outside
])
def test_sphere_in_a_box_by_symmetry(center, fraction):
    v = sphere_region_volume([center], [1.0], Region([0, 0, 0], [3, 3, 3]), 2)
    assert v[0] == pytest.approx(fraction * V1, rel=1e-8, abs=1e-12)


@pytest.mark.parametrize("h", [0.1, 0.5, 1.3, 1.9])
def test_spherical_cap_closed_form(h):
    """A plane cuts a cap of height h: V = pi h^2 (3r - h)/3 (r = 1), along each axis."""
    for axis in range(3):
        c = np.full(3, 5.0)
        c[axis] = h - 1.0                       # the face z=0 leaves a cap of height h inside
        v = sphere_region_volume([c], [1.0], Region([0, 0, 0], [10, 10, 10]), 2)
        assert v[0] == pytest.approx(np.pi * h**2 * (3 - h) / 3, rel=1e-8)


def test_sphere_in_a_cylinder():
    reg = Region([-5, -5, 0], [5, 5, 10], radius=5.0)
    on_axis = sphere_region_volume([[0, 0, 5]], [1.0], reg, 2)
    on_wall = sphere_region_volume([[5, 0, 5]], [1.0], reg, 2)
    assert on_axis[0] == pytest.approx(V1, rel=1e-8)
    # a unit sphere centred on a wall of radius 5: a little less than half (the wall is convex)
    assert 0.45 * V1 < on_wall[0] < 0.5 * V1


def test_planar_areas():
    assert disk_rectangle_area(0.0, 0.0, 1.0, -1, 1, -1, 1) == pytest.approx(np.pi, rel=1e-14)
    assert disk_rectangle_area(0.0, 0.0, 1.0, 0, 1, -1, 1) == pytest.approx(np.pi / 2, rel=1e-14)
    assert disk_rectangle_area(0.0, 0.0, 1.0, 0.5, 9, -9, 9) == pytest.approx(
        np.arccos(0.5) - 0.5 * np.sqrt(0.75), rel=1e-12)            # circular segment
    # two unit circles one radius apart: lens 2 pi/3 - sqrt(3)/2
    assert circle_lens_area(1.0, 1.0, 1.0) == pytest.approx(2 * np.pi / 3 - np.sqrt(3) / 2)


@pytest.mark.slow
@pytest.mark.parametrize("cylinder", [False, True])
def test_exact_agrees_with_monte_carlo_on_a_random_packing(cylinder):
    pk = random_packing(1500, rng=5, solid_fraction=0.57)
    lo = pk.centers.min(axis=0) + 2 * pk.mean_diameter
    hi = pk.centers.max(axis=0) - 2 * pk.mean_diameter
    reg = Region(lo, hi, 0.5 * float(np.min(hi - lo)) if cylinder else None)
    eps, err = region_porosity(pk, reg, 2)
    mc, sd = region_porosity(pk, reg, 2, method="monte-carlo", n_points=400_000, rng=1)
    assert err < 1e-4
    assert abs(eps - mc) < 4 * sd


def test_overlapping_spheres_are_counted_once():
    """Two unit spheres 1 apart inside a box: union volume 2 V1 - lens (5 pi / 12)."""
    pk = Packing([[5, 5, 5], [6, 5, 5], [20, 20, 20], [22, 20, 20], [20, 22, 20]], np.ones(5))
    eps, _ = region_porosity(pk, Region([0, 0, 0], [10, 10, 10]), 2)
    assert (1 - eps) * 1000 == pytest.approx(2 * V1 - 5 * np.pi / 12, rel=1e-8)


def test_a_sphere_inside_another_is_counted_once():
    """A sphere of radius 0.3 inside a unit sphere (off-centre): the union is the unit sphere.
    The lens formula of two crossing spheres gives a wrong, here negative, volume for it."""
    pk = Packing([[5, 5, 5], [5.4, 5, 5], [20, 20, 20]], [1.0, 0.3, 1.0])
    eps, err = region_porosity(pk, Region([0, 0, 0], [10, 10, 10]), 2)
    assert (1 - eps) * 1000 == pytest.approx(V1, rel=1e-8)
    assert 0 <= err < 1e-9
    # cut by a face (x = 5.5 through both): half the big sphere, its exact share, no bound
    eps, err = region_porosity(pk, Region([0, 0, 0], [5.5, 10, 10]), 2)
    cap = np.pi * 0.5**2 * (3 - 0.5) / 3                         # x > 5.5 of the unit sphere
    assert (1 - eps) * 550 == pytest.approx(V1 - cap, rel=1e-8)
    assert 0 <= err < 1e-9


@pytest.mark.slow
def test_triple_overlaps_are_bounded():
    """Three unit spheres at the corners of a triangle of side 1.2 overlap pairwise and all
    three share a region near the centroid: the pairwise correction subtracts that triple
    intersection once too often (the porosity comes out high); the error bound (the smallest
    lens) covers the difference to Monte Carlo, and is positive only where such a triangle
    exists."""
    s = 1.2
    tri = [[5, 5, 5], [5 + s, 5, 5], [5 + s / 2, 5 + s * np.sqrt(3) / 2, 5]]
    pk = Packing(tri, np.ones(3))
    reg = Region([0, 0, 0], [10, 10, 10])
    eps, err = region_porosity(pk, reg, 2)
    mc, sd = region_porosity(pk, reg, 2, method="monte-carlo", n_points=2_000_000, rng=3)
    lens = np.pi * (2 - s) ** 2 * (s**2 + 4 * s) / (12 * s)      # two unit spheres s apart
    assert err == pytest.approx(lens / 1000, rel=1e-6)
    assert eps - err - 4 * sd < mc < eps + 4 * sd               # the truth within the bound
    assert eps - mc > 4 * sd                                    # and the bound is needed
    _, err2 = region_porosity(Packing(tri[:2], np.ones(2)), reg, 2)
    assert err2 < 1e-9


def test_unknown_method_is_refused():
    pk = random_packing(50, rng=1)
    with pytest.raises(ValueError, match="unknown porosity method 'voxel'; choose one of exact"):
        region_porosity(pk, Region([0, 0, 0], [1, 1, 1]), 2, method="voxel")
