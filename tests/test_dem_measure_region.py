"""dem's region porosity: the volume of a sphere cut by a box or a cylinder (dem._cut_volume)
against exact volumes, and a whole region against network's exact sphere-region porosity."""

import numpy as np
import pytest

from dem import Container, Region, generate_spheres, porosity_in_region
from dem._cut_volume import cut_volume

V1 = 4.0 / 3.0 * np.pi


def cap(h):
    return np.pi * h * h * (3.0 - h) / 3.0             # unit sphere, cap of height h


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_plane_cut_gives_the_cap(axis):
    # the point count this replaced was off by up to 4.5 % of the sphere
    t = np.linspace(-0.99, 0.99, 67)
    got = []
    for ti in t:
        lo = np.full(3, -10.0)
        lo[axis] = ti
        got.append(cut_volume(np.zeros((1, 3)), [1.0], "box", lo, np.full(3, 10.0))[0])
    assert np.max(np.abs(np.array(got) - cap(1.0 - t))) < 2e-6 * V1


def test_octant_edge_and_a_sphere_about_a_cylinder_axis():
    c0, one = np.zeros((1, 3)), [1.0]
    assert cut_volume(c0, one, "box", [0, 0, 0], [5, 5, 5])[0] == pytest.approx(V1 / 8, abs=1e-8)
    assert cut_volume(c0, one, "box", [0, 0, -5], [5, 5, 5])[0] == pytest.approx(V1 / 4, abs=1e-8)
    for rad in (0.3, 0.6, 0.95, 1.5):                  # V = 4/3 pi (1 - (1 - R^2)^1.5)
        exact = V1 * (1.0 - max(1.0 - rad * rad, 0.0) ** 1.5)
        got = cut_volume(c0, one, "cylinder", [0, 0, -5], [0, 0, 5], radius=rad)[0]
        assert got == pytest.approx(exact, abs=1e-7)
    # a sphere half-way through the cylinder wall and cut by its floor: the two halves add up
    c = np.array([[0.9, 0.3, 0.2]])
    inner = cut_volume(c, one, "cylinder", [0, 0, 0], [0, 0, 5], radius=1.0)[0]
    lower = cut_volume(c, one, "cylinder", [0, 0, -5], [0, 0, 0], radius=1.0)[0]
    whole = cut_volume(c, one, "cylinder", [0, 0, -5], [0, 0, 5], radius=1.0)[0]
    assert inner + lower == pytest.approx(whole, abs=1e-7)


def test_region_porosity_against_network_exact():
    # non-overlapping spheres (random sequential addition): the two packages' region porosities
    # of a box and a cylinder cut through the spheres agree to the quadrature's 1e-6 level
    from network.packing import Packing
    from network.pores import Region as NetRegion, region_porosity

    cont = Container("box", (0.04, 0.04), 0.04)
    c, r = generate_spheres(cont, 180, 0.0025, 0.0035, np.random.default_rng(5))
    lo, hi = np.array([0.0031, 0.0047, 0.0052]), np.array([0.0343, 0.0298, 0.0361])
    mine = porosity_in_region(c, r, Region("box", tuple(lo), tuple(hi)))
    theirs, err = region_porosity(Packing(c, r), NetRegion(lo, hi), 2)
    assert mine == pytest.approx(theirs, abs=2e-6 + err)
    mid = 0.5 * (lo + hi)
    mine = porosity_in_region(c, r, Region("cylinder", (0, 0, lo[2]), (0, 0, hi[2]),
                                           radius=0.011, center_xy=(mid[0], mid[1])))
    theirs, err = region_porosity(Packing(c, r), NetRegion(lo, hi, radius=0.011), 2)
    assert mine == pytest.approx(theirs, abs=2e-6 + err)


def test_interior_keeps_a_small_square_box_off_its_walls():
    # the y margin was dropped whenever y was under 4 margins, so a 0.05 m square box counted
    # its wall layers as interior (porosity 0.4210 against 0.3808 with both margins); only a
    # slab like the thesis's rect-bin (0.25 x 0.02 m) is measured wall to wall in y
    m = 0.0129
    sq = Container("box", (0.05, 0.05), 0.04).interior(m, 0.035)
    assert sq.lo[:2] == pytest.approx((-0.025 + m, -0.025 + m))
    slab = Container("box", (0.25, 0.02), 0.25).interior(m, 0.2)
    assert slab.lo[:2] == pytest.approx((-0.125 + m, -0.01)) and slab.hi[1] == pytest.approx(0.01)
