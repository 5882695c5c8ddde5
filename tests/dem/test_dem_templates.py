"""Multi-sphere grain templates: axes and volume within 2 %, one body, bad input."""

import numpy as np
import pytest

from dem.templates import (TEMPLATE_GRAINS, check_template, library_template, read_template, sphere_template,
                           template_from_axes)
from dem.grains import grain
from dem._rigid import union_mass_properties


@pytest.mark.slow
@pytest.mark.parametrize("name", TEMPLATE_GRAINS)
def test_library_template_matches_axes_and_volume(name):
    t = library_template(name)
    axes = np.array(grain(name).axes_mm.value) * 1e-3
    np.testing.assert_allclose(t.extent_m, np.sort(axes)[::-1], rtol=0.02)
    v_ell = np.pi / 6 * np.prod(axes)
    # the union's volume, measured afresh with other QMC points (not the construction's)
    v = union_mass_properties(t.positions, t.radii, seed=777)["volume"]
    assert abs(v / v_ell - 1) < 0.02
    assert t.volume_error_m3 / t.volume_m3 < 2e-3
    check_template(t.positions, t.radii)  # one body
    assert t.n >= 5 and np.allclose(union_mass_properties(t.positions, t.radii)["centroid"], 0, atol=1e-3 * t.extent_m[0])
    assert t.inertia_unit[0] <= t.inertia_unit[1] <= t.inertia_unit[2]  # x is the long axis


def test_union_volume_of_two_overlapping_spheres_is_not_the_sum():
    # two unit spheres at distance 1: union = 2 V - lens, lens = 5 pi / 12 (closed form)
    mp = union_mass_properties([[0, 0, 0], [1, 0, 0]], [1, 1])
    exact = 2 * 4 / 3 * np.pi - 5 * np.pi / 12
    assert abs(mp["volume"] - exact) < 4 * mp["volume_error"] + 1e-3 * exact
    assert mp["centroid"][0] == pytest.approx(0.5, abs=2e-3)


def test_sphere_template_is_exact():
    t = sphere_template(0.003)
    assert t.n == 1 and t.volume_m3 == 4 / 3 * np.pi * 0.003**3 and t.volume_error_m3 == 0


@pytest.mark.slow
def test_template_from_axes_refuses_too_few_spheres():
    with pytest.raises(ValueError, match="max_spheres"):
        template_from_axes([9.25e-3, 7.87e-3, 3.86e-3], max_spheres=9)


@pytest.mark.parametrize("body, match", [
    ("x,y,z,r\n0,0,0,1\n1,0,0,nan\n", "row 3: not a finite number"),
    ("x,y,z,r\n0,0,0,1\n1,0,0,0\n", "row 3: radius 0 must be positive"),
    ("x,y,z,r\n0,0,0,1\n1,0,0,-1\n", "row 3: radius -1 must be positive"),
    ("x,y,z,r\n0,0,0,1\n1,0,0,1\n5,0,0,1\n", "row 4: sphere does not overlap into one body with row 2"),
    ("x,y,z,r\n", "no spheres"),
    ("", "row 1: expected the header"),
    ("x,y,z,r\n0,0,0\n", "row 2: expected four numbers"),
])
def test_bad_template_file_names_the_row(tmp_path, body, match):
    f = tmp_path / "t.csv"
    f.write_text(body)
    with pytest.raises(ValueError, match=match) as e:
        read_template(f)
    assert "\n" not in str(e.value)


def test_user_template_units(tmp_path):
    f = tmp_path / "peanut.csv"
    f.write_text("x,y,z,r\n-1,0,0,1.2\n1,0,0,1.2\n")
    mm, m = read_template(f, units="mm"), read_template(f, units="m")
    assert mm.volume_m3 == pytest.approx(m.volume_m3 * 1e-9, rel=1e-9)
    np.testing.assert_allclose(mm.extent_m, [4.4e-3, 2.4e-3, 2.4e-3], rtol=2e-3)  # frame from QMC inertia
