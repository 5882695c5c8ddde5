"""dem's region porosity is the project's one estimator (network.core.region_porosity) on dem's
vertical box and cylinder regions: exact against closed forms, with a cylinder about any axis
point (center_xy), and the region's own volume."""

import numpy as np
import pytest

from dem import Container, Region, generate_spheres, porosity_in_region

V1 = 4.0 / 3.0 * np.pi


def cap(h):
    return np.pi * h * h * (3.0 - h) / 3.0             # unit sphere, cap of height h


@pytest.mark.parametrize("z_floor", [-0.99, -0.4, 0.0, 0.55, 0.99])
def test_a_box_floor_cuts_the_cap(z_floor):
    box = Region("box", (-10.0, -10.0, z_floor), (10.0, 10.0, 10.0))
    eps = porosity_in_region(np.zeros((1, 3)), [1.0], box)
    assert (1 - eps) * box.volume == pytest.approx(cap(1.0 - z_floor), abs=5e-9 * V1)  # 16 nodes


@pytest.mark.parametrize("rad", [0.3, 0.6, 0.95, 1.5])
def test_a_cylinder_about_an_off_origin_axis_cuts_the_sphere_exactly(rad):
    """V = 4/3 pi (1 - (1 - R^2)^1.5) of a unit sphere centred on the cylinder's axis, the axis
    at (0.7, -0.2) as center_xy places it."""
    cyl = Region("cylinder", (0, 0, -5), (0, 0, 5), radius=rad, center_xy=(0.7, -0.2))
    eps = porosity_in_region(np.array([[0.7, -0.2, 0.3]]), [1.0], cyl)
    exact = V1 * (1.0 - max(1.0 - rad * rad, 0.0) ** 1.5)
    assert (1 - eps) * cyl.volume == pytest.approx(exact, abs=1e-7)


def test_random_spheres_box_and_cylinder_add_up():
    """Non-overlapping spheres: the solid in a box is the sum of the solid in two halves cut
    at any height, for a box and for a cylinder alike."""
    cont = Container("box", (0.04, 0.04), 0.04)
    c, r = generate_spheres(cont, 180, 0.0025, 0.0035, np.random.default_rng(5))
    lo, hi = np.array([0.0031, 0.0047, 0.0052]), np.array([0.0343, 0.0298, 0.0361])
    mid = 0.5 * (lo + hi)
    for kw in ({"kind": "box"}, {"kind": "cylinder", "radius": 0.011,
                                  "center_xy": (mid[0], mid[1])}):
        def solid(z0, z1):
            reg = Region(lo=(lo[0], lo[1], z0), hi=(hi[0], hi[1], z1), **kw)
            return (1 - porosity_in_region(c, r, reg)) * reg.volume
        assert solid(lo[2], hi[2]) == pytest.approx(solid(lo[2], 0.02) + solid(0.02, hi[2]),
                                                    rel=1e-9)


def test_interior_keeps_a_small_square_box_off_its_walls():
    # the y margin was dropped whenever y was under 4 margins, so a 0.05 m square box counted
    # its wall layers as interior (porosity 0.4210 against 0.3808 with both margins); only a
    # slab like the thesis's rect-bin (0.25 x 0.02 m) is measured wall to wall in y
    m = 0.0129
    sq = Container("box", (0.05, 0.05), 0.04).interior(m, 0.035)
    assert sq.lo[:2] == pytest.approx((-0.025 + m, -0.025 + m))
    slab = Container("box", (0.25, 0.02), 0.25).interior(m, 0.2)
    assert slab.lo[:2] == pytest.approx((-0.125 + m, -0.01)) and slab.hi[1] == pytest.approx(0.01)
