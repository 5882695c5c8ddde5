"""Branched-path model (thesis 3.5.1, Eqs. 3.28-3.39): closed-form checks."""

import numpy as np
import pytest

from network.paths import (
    branched_pressure_drop,
    branching_multiplier,
    equivalent_diameter,
    laminar_pipe_dp,
    local_width,
)

MU = 1.932e-5  # thesis air viscosity, Pa s


def _straight_chain(m, seg, d, rng):
    """m tetrahedra along a random straight line: C0 -> Ct -> C1 collinear, one open exit."""
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    c_in = np.arange(m)[:, None] * 2 * seg * u
    c_tet = c_in + seg * u
    c_out = np.repeat(c_tet[:, None, :], 3, axis=1) + rng.normal(size=(m, 3, 3)) * seg
    c_out[:, 0] = c_tet + seg * u  # the only open daughter continues straight on
    d_out = np.zeros((m, 3))
    d_out[:, 0] = d
    return c_in, c_tet, c_out, np.full(m, d), d_out


@pytest.mark.parametrize("branches", ["all", "path"])
def test_no_branching_is_hagen_poiseuille(branches):
    # one open daughter each: the chain is a straight pipe of length 2 m seg, so
    # dP = 128 mu Q L / (pi D^4) (Hagen-Poiseuille), whatever the closed daughters' angles
    rng = np.random.default_rng(1)
    m, seg, d, q = 50, 1.3e-3, 2.8e-3, 3.0e-8
    c_in, c_tet, c_out, d_in, d_out = _straight_chain(m, seg, d, rng)
    res = branched_pressure_drop(c_in, c_tet, c_out, d_in, d_out, np.zeros(m, int), q,
                                 branches=branches, mu_pa_s=MU)
    hp = 128 * MU * q * (2 * m * seg) / (np.pi * d**4)
    assert res.total_pa == pytest.approx(hp, rel=1e-12)
    np.testing.assert_allclose(res.theta_rad[:, 0], 0.0, atol=1e-7)


def test_darcy_factor_form_equals_poiseuille():
    # Eq. 3.30 with f_D = 64/Re (Eq. 3.33-3.35) at rho = 1.2 kg/m3 equals 128 mu Q L / (pi D^4)
    q, length, d, rho = 2e-7, 0.01, 3e-3, 1.2
    v = 4 * q / (np.pi * d**2)
    re = rho * d * v / MU
    darcy = 64 / re * length / d * rho * v**2 / 2
    assert laminar_pipe_dp(q, length, d, mu_pa_s=MU) == pytest.approx(darcy, rel=1e-12)


def test_multipliers_lee_2007():
    # MFx3 = 3 - 2 cos(theta), MFx2 = 2 - cos(theta): 1 straight on, 3 and 2 at 90 degrees
    th = np.array([0.0, np.pi / 3, np.pi / 2])
    np.testing.assert_allclose(branching_multiplier(th, "MFx3"), [1.0, 2.0, 3.0], atol=1e-15)
    np.testing.assert_allclose(branching_multiplier(th, "MFx2"), [1.0, 1.5, 2.0], atol=1e-15)
    with pytest.raises(ValueError, match="MFx4"):
        branching_multiplier(th, "MFx4")


def test_symmetric_branching_matches_hand_sum():
    # a T-junction: mother along +z, three equal daughters at 90 degrees: Q splits in three
    # (Eq. 3.38), each loses MFx3(90 deg) = 3 times the 2100/Re pipe loss (Eq. 3.36-3.37)
    q, d, seg = 1e-7, 3e-3, 1e-3
    c_in = np.array([[0.0, 0.0, -seg]])
    c_tet = np.zeros((1, 3))
    ang = np.array([0, 2 * np.pi / 3, 4 * np.pi / 3])
    c_out = np.stack([seg * np.cos(ang), seg * np.sin(ang), np.zeros(3)], axis=1)[None]
    res = branched_pressure_drop(c_in, c_tet, c_out, [d], [[d, d, d]], [1], q, mu_pa_s=MU,
                                 branches="all")
    straight = 128 * MU * q * seg / (np.pi * d**4)
    branch = 3.0 * (2100 / 64) * 128 * MU * (q / 3) * seg / (np.pi * d**4)
    assert res.dp_straight_pa[0] == pytest.approx(straight, rel=1e-12)
    np.testing.assert_allclose(res.dp_branch_pa[0], branch, rtol=1e-12)
    assert res.total_pa == pytest.approx(straight + 3 * branch, rel=1e-12)
    path = branched_pressure_drop(c_in, c_tet, c_out, [d], [[d, d, d]], [1], q, mu_pa_s=MU,
                                  branches="path")
    assert path.total_pa == pytest.approx(straight + branch, rel=1e-12)
    # laminar: linear in the flow rate
    res2 = branched_pressure_drop(c_in, c_tet, c_out, [d], [[d, d, d]], [1], 2 * q, mu_pa_s=MU,
                                  branches="all")
    assert res2.total_pa == pytest.approx(2 * res.total_pa, rel=1e-12)


def test_local_widths():
    # Eq. 3.24: d = 2 sqrt(S / pi); average = mean of the two diameters; closed face -> 0
    full = np.array([np.pi * 4.0, np.pi * 4.0])
    opened = np.array([np.pi * 1.0, 0.0])
    np.testing.assert_allclose(local_width(full, opened, "max"), [4.0, 0.0])
    np.testing.assert_allclose(local_width(full, opened, "min"), [2.0, 0.0])
    np.testing.assert_allclose(local_width(full, opened, "average"), [3.0, 0.0])
    assert equivalent_diameter(-1.0) == 0.0


def test_bad_input_raises():
    with pytest.raises(ValueError, match="no open outlet"):
        branched_pressure_drop(np.zeros((1, 3)), np.ones((1, 3)), np.ones((1, 3, 3)), [1.0],
                               [[0.0, 0.0, 0.0]], [0], 1.0)
    with pytest.raises(ValueError, match="expected c_in"):
        branched_pressure_drop(np.zeros((2, 3)), np.ones((1, 3)), np.ones((1, 3, 3)), [1.0],
                               [[1.0, 0.0, 0.0]], [0], 1.0)
    with pytest.raises(ValueError, match="branches"):
        branched_pressure_drop(np.zeros((1, 3)), np.ones((1, 3)), np.ones((1, 3, 3)), [1.0],
                               [[1.0, 0.0, 0.0]], [0], 1.0, branches="some")


def test_unequal_daughters_split_by_cross_section():
    # Eq. 3.38: Q_i = Q0 D_i^2 / sum D_j^2, so daughters of 2d and d (third closed) carry
    # 4/5 and 1/5 of Q0 at one velocity; each loses f(theta) 2 * 2100 mu Q_i L_i / (pi D_i^4)
    # (Eqs. 3.36-3.39), the closed one nothing; 'all' sums both, 'path' keeps the exit's
    q, d, seg = 2e-7, 1.5e-3, 1e-3
    c_in = np.array([[0.0, 0.0, -seg]])
    c_tet = np.zeros((1, 3))
    c_out = np.array([[[0.0, 0.0, seg], [seg, 0.0, 0.0], [0.0, seg, 0.0]]])  # 0 and 90 deg
    d_out = np.array([[2 * d, d, 0.0]])
    res = branched_pressure_drop(c_in, c_tet, c_out, [2 * d], d_out, [1], q, mu_pa_s=MU,
                                 branches="all")
    b0 = 1.0 * 2 * 2100 * MU * (0.8 * q) * seg / (np.pi * (2 * d) ** 4)   # straight on: f = 1
    b1 = 3.0 * 2 * 2100 * MU * (0.2 * q) * seg / (np.pi * d**4)           # 90 deg: MFx3 = 3
    np.testing.assert_allclose(res.dp_branch_pa[0], [b0, b1, 0.0], rtol=1e-12)
    np.testing.assert_allclose(res.theta_rad[0, :2], [0.0, np.pi / 2], atol=1e-12)
    straight = laminar_pipe_dp(q, seg, 2 * d, mu_pa_s=MU)
    assert res.total_pa == pytest.approx(straight + b0 + b1, rel=1e-12)
    path = branched_pressure_drop(c_in, c_tet, c_out, [2 * d], d_out, [1], q, mu_pa_s=MU)
    assert path.total_pa == pytest.approx(straight + b1, rel=1e-12)
    # a series of M identical tetrahedra loses M times one
    m = 7
    rep = branched_pressure_drop(np.repeat(c_in, m, 0), np.repeat(c_tet, m, 0),
                                 np.repeat(c_out, m, 0), np.full(m, 2 * d),
                                 np.repeat(d_out, m, 0), np.ones(m, int), q, mu_pa_s=MU)
    assert rep.total_pa == pytest.approx(m * path.total_pa, rel=1e-12)
