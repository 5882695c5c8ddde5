"""Closed-form checks of throats geometry (open area, contact type, canonical form)."""

import numpy as np
import pytest

from throats import (canonical_form, contact_type, open_area, triangle_vertices,
                     validate_throats)


def test_open_area_matches_closed_forms():
    # three touching unit disks leave the cusped region sqrt(3) - pi/2 (STYLE.md sec. 3);
    # a 3-4-5 triangle with r = 0.5 sectors adding up to half a disk: 6 - pi/8
    got = open_area([[1, 1, 1], [0.5, 0.5, 0.5]], [[2, 2, 2], [3, 4, 5]])
    np.testing.assert_allclose(got, [np.sqrt(3) - np.pi / 2, 6 - np.pi / 8], rtol=1e-12)


def test_open_area_overlapping_disks_adds_back_half_lenses():
    # equilateral side 1.8, unit disks: each pair overlaps in a lens (circle-circle
    # intersection area 2r^2 acos(d/2r) - (d/2) sqrt(4r^2 - d^2)); half of each lens lies in
    # the triangle; no triple overlap (circumradius 1.039 > 1).
    a, d = 1.8, 1.8
    lens = 2 * np.arccos(d / 2) - d / 2 * np.sqrt(4 - d**2)
    want = np.sqrt(3) / 4 * a**2 - np.pi / 2 + 1.5 * lens
    got = open_area([[1, 1, 1]], [[a, a, a]])
    np.testing.assert_allclose(got, [want], rtol=1e-12)


def test_open_area_zero_when_disks_cover_triangle():
    # equilateral side 1.6 has circumradius 0.924 < 1; r >= l (a disk holding the other
    # centres) is not a valid throat but its area is still exact
    got = open_area([[1, 1, 1], [0.9, 1.2, 1.1], [1, 1, 1]], [[1.6, 1.6, 1.6], [1.5, 1.5, 1.6],
                                                             [0.8, 0.8, 0.8]])
    np.testing.assert_allclose(got, [0.0, 0.0, 0.0], atol=1e-14)


@pytest.mark.parametrize("radii, sides", [
    ([1.2, 0.7, 1.0], [3.0, 1.6, 3.3]),      # disk 1 nearly reaches side 23
    ([0.9, 0.8, 1.4], [2.4, 3.0, 2.2]),      # disk 3 crosses side 12: region splits in two
    ([1.0, 1.1, 0.9], [1.9, 2.6, 1.7]),      # two overlapping pairs (type c)
])
def test_open_area_matches_monte_carlo(radii, sides):
    # Monte Carlo estimate with a fixed seed, 6 standard errors
    rng = np.random.default_rng(7)
    v = triangle_vertices([sides])[0]
    m = 400_000
    u = rng.random((m, 2))
    flip = u.sum(1) > 1
    u[flip] = 1 - u[flip]
    p = v[0] + u[:, :1] * (v[1] - v[0]) + u[:, 1:] * (v[2] - v[0])
    free = np.ones(m, dtype=bool)
    for i in range(3):
        free &= np.linalg.norm(p - v[i], axis=1) > radii[i]
    tri = 0.5 * abs(np.cross(np.r_[v[1] - v[0], 0], np.r_[v[2] - v[0], 0])[2])
    est = tri * free.mean()
    se = tri * np.sqrt(free.mean() * (1 - free.mean()) / m)
    assert abs(open_area([radii], [sides])[0] - est) < 6 * se


def test_open_area_scales_quadratically_and_is_permutation_invariant():
    r = np.array([[0.9, 1.1, 1.0]])
    s = np.array([[2.3, 2.0, 2.5]])
    a0 = open_area(r, s)[0]
    assert open_area(r * 3.5e-3, s * 3.5e-3)[0] == pytest.approx(a0 * 3.5e-3**2, rel=1e-12)
    # vertex order (2, 1, 3): radii [r2, r1, r3], sides [l21, l23, l13]
    assert open_area(r[:, [1, 0, 2]], s[:, [0, 2, 1]])[0] == pytest.approx(a0, rel=1e-12)


def test_contact_types():
    r = [[1, 1, 1]] * 5
    s = [[2.5, 2.5, 2.5], [2.0, 2.5, 2.5], [1.9, 2.0, 2.5], [2, 2, 2], [2 + 1e-12, 2, 2]]
    assert contact_type(r, s).tolist() == ["a", "b", "c", "d", "d"]


def test_canonical_form_invariant_under_permutation_and_scale():
    r = np.array([0.9, 1.3, 1.05])
    s = np.array([2.4, 2.1, 2.7])  # l12, l13, l23
    pairs = {(0, 1): 0, (0, 2): 1, (1, 2): 2}
    rows_r, rows_s = [], []
    for perm in [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]:
        a, b, c = perm
        rows_r.append(r[[a, b, c]] * 7.3)
        rows_s.append([s[pairs[tuple(sorted((a, b)))]] * 7.3, s[pairs[tuple(sorted((a, c)))]] * 7.3,
                       s[pairs[tuple(sorted((b, c)))]] * 7.3])
    rc, sc = canonical_form(rows_r, rows_s)
    np.testing.assert_allclose(rc, np.repeat(rc[:1], 6, axis=0), rtol=1e-14)
    np.testing.assert_allclose(sc, np.repeat(sc[:1], 6, axis=0), rtol=1e-14)
    assert rc.mean(axis=1) == pytest.approx(np.ones(6))
    assert rc[0, 0] == pytest.approx(0.9 / r.mean())


def test_validate_throats_flags_bad_rows_with_messages():
    r = np.array([[1, 1, 1], [np.nan, 1, 1], [1, -1, 1], [1, 1, 1], [1, 1, 1], [3, 1, 1]])
    s = np.array([[2.2, 2.2, 2.2], [2, 2, 2], [2, 2, 2], [1, 2, 3], [1, 5, 1], [2, 2, 2]])
    r0, s0 = r.copy(), s.copy()
    ok, msg = validate_throats(r, s)
    # row 5, a disk containing another vertex, is a valid triangle of disks
    assert ok.tolist() == [True, False, False, False, False, True]
    assert msg[0] == "" and msg[5] == ""
    assert "non-finite" in msg[1] and "radius <= 0" in msg[2]
    assert "triangle" in msg[3] and "triangle" in msg[4]
    np.testing.assert_array_equal(r, r0)  # inputs unchanged
    assert np.isnan(open_area(r, s)[1:5]).all()


def test_bad_shapes_raise():
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        open_area([[1, 1]], [[2, 2]])


@pytest.mark.parametrize("scale", [1e-300, 1e-100, 1.0, 1e80, 1e200, 1e300])
def test_triangle_test_is_scale_free(scale):
    """The triangle test divides by the longest side: at 1e80 and up the squared sides
    overflowed (warning, 'do not form a triangle'), at 1e-100 and down they underflowed."""
    r = scale * np.array([[1.0, 1, 1], [1, 1, 1], [1, 1, 1]])
    s = scale * np.array([[2.2, 2.2, 2.2], [1, 1, 3], [1, 2, 3]])
    with np.errstate(all="raise"):
        ok, msg = validate_throats(r, s)
    assert ok.tolist() == [True, False, False]
    assert msg[0] == "" and "do not form a triangle" in msg[1] and "do not form" in msg[2]
