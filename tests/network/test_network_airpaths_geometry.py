"""Path geometry with closed-form answers: angles (thesis Eq. 3.25), the smoothing factor
(Eq. 3.26), smoothed length (Eq. 3.27), tortuosity, bed depth (Appendix D's L0) and the full /
open areas of a face (Eqs. 3.18, 3.23, 3.24)."""

import numpy as np
import pytest

from network.paths import (
    OMEGA_A,
    AirflowPath,
    bed_depth,
    eq323_negative,
    face_areas,
    interior_angles,
    path_length,
    smoothed_length,
    smoothing_factor,
    turning_angles,
)

#: Eq. 3.26 at 180 deg with the thesis's omega_a = 0.1, omega_b = 90: e^9 / (1 + e^9)
F180 = np.exp(9.0) / (1.0 + np.exp(9.0))


def _straight(n, s, direction=(0.0, 0.0, 1.0)):
    u = np.asarray(direction, float) / np.linalg.norm(direction)
    return np.arange(n + 1)[:, None] * s * u


def test_straight_path_has_no_turns_and_tortuosity_one():
    # n collinear segments: every interior angle 180 deg (Eq. 3.25), no turning, length n s;
    # Eq. 3.27 gives s + (n - 1) s F(180) (half the end segments + half of each pair)
    n, s = 12, 1.5e-3
    pts = _straight(n, s, (1.0, 2.0, 2.0))
    # arccos near -1 resolves angles to about sqrt(eps) rad = 1e-6 deg
    np.testing.assert_allclose(interior_angles(pts), 180.0, atol=1e-5)
    np.testing.assert_allclose(turning_angles(pts), 0.0, atol=1e-5)
    assert path_length(pts) == pytest.approx(n * s, rel=1e-14)
    assert smoothed_length(pts) == pytest.approx(s + (n - 1) * s * F180, rel=1e-12)
    # the same polyline as a path record along z: raw and span tortuosity are 1
    pz = _straight(n, s)
    path = AirflowPath(kind="widest", method="build", entry_xy=np.zeros(2), axis="z",
                       status="ok", tetra_vertices=np.zeros((n, 4), int),
                       exit_local=np.zeros(n, int), points=pz, widths_m=np.full(n, 2e-3),
                       length_m=path_length(pz), smoothed_length_m=smoothed_length(pz),
                       depth_m=n * s, turning_angles_deg=turning_angles(pz),
                       pores=np.full(n, -1))
    assert path.tortuosity_raw == pytest.approx(1.0, rel=1e-14)
    assert path.tortuosity_span == pytest.approx(1.0, rel=1e-14)
    assert path.tortuosity == pytest.approx((1 + (n - 1) * F180) / n, rel=1e-12)
    summary = path.summary()
    assert summary["turning_below_30deg"] == 1.0
    assert summary["bottleneck_width_m"] == 2e-3
    assert summary["mean_width_m"] == pytest.approx(2e-3, rel=1e-15)


def test_right_angle_staircase():
    # x and z steps alternate: every interior angle is 90 deg, every turn 90 deg, the
    # smoothing factor is exactly 1/2 (Eq. 3.26 at omega_b), so Eq. 3.27 gives s + (n-1) s / 2;
    # raw tortuosity over the z extent of n/2 steps is 2 (the Manhattan length)
    n, s = 10, 2e-3
    steps = np.zeros((n, 3))
    steps[0::2, 2] = s
    steps[1::2, 0] = s
    pts = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(interior_angles(pts), 90.0, atol=1e-9)
    np.testing.assert_allclose(turning_angles(pts), 90.0, atol=1e-9)
    assert smoothed_length(pts) == pytest.approx(s + (n - 1) * s / 2, rel=1e-12)
    assert path_length(pts) / np.ptp(pts[:, 2]) == pytest.approx(2.0, rel=1e-14)


def test_three_dimensional_zigzag_and_reversal():
    # x, y, z unit steps in turn: consecutive steps are orthogonal, so 90 deg everywhere;
    # a full reversal is 0 deg (turn 180) with factor 1 / (1 + e^9) (Eq. 3.26)
    steps = np.tile(np.eye(3), (3, 1))
    pts = np.concatenate([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(interior_angles(pts), 90.0, atol=1e-9)
    back = np.array([[0, 0, 0], [0, 0, 1], [0, 0, 0]], float)
    assert interior_angles(back)[0] == pytest.approx(0.0, abs=1e-6)
    assert turning_angles(back)[0] == pytest.approx(180.0, abs=1e-6)
    assert smoothed_length(back) == pytest.approx(1.0 + 1.0 / (1.0 + np.exp(9.0)), rel=1e-12)
    # equilateral corner: 60 deg
    tri = np.array([[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    assert interior_angles(tri)[0] == pytest.approx(60.0, abs=1e-9)


def test_smoothing_factor_is_the_logistic_of_eq_3_26():
    # symmetric about omega_b: f(90 + d) + f(90 - d) = 1; f(100) = e / (1 + e); slope at the
    # midpoint omega_a / 4 per degree; a steeper omega_a moves f(180) towards 1
    d = np.array([5.0, 30.0, 90.0])
    np.testing.assert_allclose(smoothing_factor(90 + d) + smoothing_factor(90 - d), 1.0,
                               atol=1e-15)
    assert smoothing_factor(100.0) == pytest.approx(np.e / (1 + np.e), rel=1e-14)
    slope = (smoothing_factor(90.0 + 1e-4) - smoothing_factor(90.0 - 1e-4)) / 2e-4
    assert slope == pytest.approx(OMEGA_A / 4, rel=1e-6)
    assert smoothing_factor(180.0) == pytest.approx(F180, rel=1e-14)
    assert smoothing_factor(120.0, omega_b_deg=120.0) == 0.5
    assert smoothing_factor(-1e6) == 0.0 and smoothing_factor(1e6) == 1.0  # no overflow


def test_appendix_d_rule_at_a_right_angle():
    # Appendix D takes (180/3.14) cos(omega) with no arccos: 0 at a right angle (Eq. 3.25: 90)
    pts = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 1]], float)
    assert interior_angles(pts, rule="appendix-d")[0] == pytest.approx(0.0, abs=1e-12)
    assert interior_angles(pts)[0] == pytest.approx(90.0, abs=1e-12)


def test_lengths_are_rigid_motion_invariant():
    rng = np.random.default_rng(4)
    pts = np.cumsum(rng.normal(size=(30, 3)) * 1e-3, axis=0)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    moved = pts @ q.T + np.array([0.3, -1.0, 2.0])
    assert path_length(moved) == pytest.approx(path_length(pts), rel=1e-12)
    assert smoothed_length(moved) == pytest.approx(smoothed_length(pts), rel=1e-12)
    np.testing.assert_allclose(interior_angles(moved), interior_angles(pts), atol=1e-7)


def test_points_are_checked():
    with pytest.raises(ValueError, match="shape"):
        path_length(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="finite"):
        smoothed_length([[0, 0, 0], [np.nan, 0, 0]])
    assert interior_angles(np.zeros((2, 3))).size == 0
    assert smoothed_length([[0, 0, 0], [0, 0, 3.0]]) == 3.0


def test_bed_depth_is_centre_span_plus_mean_diameter():
    # Appendix D: max(z) - min(z) + 0.0065 for 6.5 mm beans
    c = np.array([[0, 0, 0.01], [0.1, 0, 0.05], [0, 0.2, 0.03]])
    r = np.full(3, 3.25e-3)
    assert bed_depth(c, r) == pytest.approx(0.04 + 0.0065, rel=1e-14)
    assert bed_depth(c, r, "x") == pytest.approx(0.1 + 0.0065, rel=1e-14)


@pytest.mark.parametrize("r_over_a, open_over_a2", [
    (0.25, np.sqrt(3) / 4 - np.pi * 0.25**2 / 2),   # three 60-degree sectors: pi r^2 / 2
    (0.5, np.sqrt(3) / 4 - np.pi / 8),               # touching disks: 0.0403 a^2
    (0.6, 0.0),                                       # r > circumradius a/sqrt(3): covered
])
def test_open_area_of_an_equilateral_face(r_over_a, open_over_a2):
    # Eq. 3.18 (Heron): sqrt(3)/4 a^2; Eq. 3.23: minus the three sectors (exact without
    # overlaps); Eq. 3.24: d = 2 sqrt(S / pi)
    a = 6.5e-3
    pts = np.array([[0, 0, 0], [a, 0, 0], [a / 2, a * np.sqrt(3) / 2, 0]])
    full, opened = face_areas(pts, np.full(3, r_over_a * a), [[0, 1, 2]])
    assert full[0] == pytest.approx(np.sqrt(3) / 4 * a**2, rel=1e-14)
    assert opened[0] == pytest.approx(open_over_a2 * a**2, rel=1e-9, abs=1e-18)
    # reselection rule 2 (Fig. 3.8): Eq. 3.23 negative only when the sectors exceed the face
    assert eq323_negative(pts, np.full(3, r_over_a * a), [[0, 1, 2]])[0] == (
        np.sqrt(3) / 4 < 3 * np.pi / 6 * r_over_a**2)
