"""The pieces of the conduit window law: the onset form against Navier-Stokes through single
constrictions, and in closed form the onset flow of a conduit, the expansion against a turned
jet, the turning cosines, the loss and onset coefficients of one window (docs/inertial-flow.md).
"""

import numpy as np
import pytest

import throats
from network.conductance import (expansion_coefficient, inertial_coefficients, onset_scales,
                                 turning_cosines)
from network.packing import Packing
from network.pores import tessellate
from network.flow import conduit_flow, solve_inertial

#: Axisymmetric Navier-Stokes through single sphere-ring constrictions
#: (``docs/scripts/inertial_constriction_ns.py``, sphere radius a = 1): excess loss coefficient
#: k = (dp - dp_Stokes)/(rho u_w^2/2) at window Reynolds numbers NS_RE, per (r_w, h); halving the
#: cells moves k by < 0.1 %. The derivation of the onset form and of the smooth contraction.
NS_RE = np.array([1, 2, 5, 10, 20, 50, 100, 200], dtype=float)
NS_K = {
    (0.30, 0.6): [0.01415, 0.02827, 0.07002, 0.13515, 0.23477, 0.33995, 0.35434, 0.33429],
    (0.15, 0.6): [0.01350, 0.02700, 0.06758, 0.13551, 0.26791, 0.51557, 0.62087, 0.63970],
    (0.45, 0.6): [0.01222, 0.02435, 0.05951, 0.11026, 0.17425, 0.21984, 0.21435, 0.19298],
    (0.30, 0.4): [0.00710, 0.01413, 0.03434, 0.06269, 0.09644, 0.11704, 0.11042, 0.09540],
    (0.30, 0.8): [0.01805, 0.03610, 0.09034, 0.18052, 0.34491, 0.57721, 0.64643, 0.64612],
    (0.20, 0.5): [0.01223, 0.02444, 0.06071, 0.11844, 0.21302, 0.33090, 0.35573, 0.33969],
}
#: their common low-Re slope per h/a, dk/dRe_w = c_1 h/a
NS_C1 = 0.0235


@pytest.mark.parametrize("geom", sorted(NS_K))
def test_ns_constrictions_follow_the_onset_form(geom):
    # k = k_peak t/sqrt(1+t^2), t = Re_w c1 (h/a) / k_peak: the low-Re slope is c1 h/a
    # within 25 % (h/a 0.4-0.8, sigma 0.18-0.61) and the shape within 0.09 of k_peak up to
    # Re_w 100 (past its peak k falls again, to 0.82-1.0 of it at Re_w 200)
    rw, h = geom
    k = np.asarray(NS_K[geom])
    slope = k[0] / NS_RE[0]
    assert slope == pytest.approx(NS_C1 * h, rel=0.25)
    peak = k.max()
    t = NS_RE * slope / peak
    upto = NS_RE <= 100
    np.testing.assert_allclose((k / peak)[upto], (t / np.sqrt(1 + t * t))[upto], atol=0.09)
    assert k[-1] / peak > 0.8
    # the asymptote is below Borda-Carnot (1 - sigma)^2 and above 3/4 of it: no vena
    # contracta loss at a sphere-rounded window (no contraction loss in the window law)
    rb = rw + 1.0 - np.sqrt(1.0 - h * h)
    bc = (1 - rw**2 / rb**2) ** 2
    assert 0.75 * bc < peak < bc


def test_throat_onset_conduit_flow():
    rng = np.random.default_rng(3)
    n = 2000
    g, K = 10 ** rng.uniform(-3, 3, n), 10 ** rng.uniform(-3, 3, (n, 2))
    c = 10 ** rng.uniform(-3, 3, (n, 2))
    dp = 10 ** rng.uniform(-7, 7, n) * rng.choice([-1.0, 1.0], n)
    q, w = conduit_flow(dp, g, K, onset_scale=c)
    fwd = dp >= 0
    k, cc = np.where(fwd, K[:, 0], K[:, 1]), np.where(fwd, c[:, 0], c[:, 1])
    t = cc * np.abs(q)
    np.testing.assert_allclose(q / g + k * q * np.abs(q) * t / np.sqrt(1 + t * t), dp,
                               rtol=1e-12)
    q2, _ = conduit_flow(dp * (1 + 1e-7), g, K, onset_scale=c)
    np.testing.assert_allclose((q2 - q) / (dp * 1e-7), w, rtol=1e-5)
    # warm start from any flows of either sign, above or below the root: the same root (the
    # residual is convex and increasing; from below the first step overshoots it)
    start = q * 10 ** rng.uniform(-2, 2, n) * rng.choice([-1.0, 1.0], n, p=[0.1, 0.9])
    q3, w3 = conduit_flow(dp, g, K, onset_scale=c, q_start=start)
    np.testing.assert_allclose(q3, q, rtol=1e-13)
    np.testing.assert_allclose(w3, w, rtol=1e-12)
    # Re^2 onset: excess / viscous drop = K g c q^2 at small flow; K q|q| at large flow
    q, _ = conduit_flow(np.array([1e-6]), np.ones(1), np.ones(1), onset_scale=np.ones(1))
    assert (1e-6 - q[0]) / q[0] == pytest.approx(q[0] ** 2, rel=1e-5)
    q, _ = conduit_flow(np.array([1e8]), np.ones(1), np.ones(1), onset_scale=np.ones(1))
    assert q[0] ** 2 == pytest.approx(1e8, rel=1e-3)
    conns = np.array([[0, 1], [1, 2]])
    with pytest.raises(ValueError, match="onset_scale must have 2 rows"):
        solve_inertial(3, conns, np.ones(2), np.ones(2), [0], [2], [1.0],
                       onset_scale=np.ones(3))
    # two conduits in series, 1 m3/s: each drop is 1 + 1 * 1/sqrt(2) (t = 1)
    pts = solve_inertial(3, conns, np.ones(2), np.ones(2), [0], [2], [1.0],
                         onset_scale=np.ones(2))
    assert pts[0].converged
    assert pts[0].dp_pa == pytest.approx(2 * (1 + 1 / np.sqrt(2)), rel=1e-10)


def test_expansion_against_the_outflow_direction():
    # momentum balance with the jet at angle theta: K = 1 - 2 s cos + s^2 (flat profile)
    s = np.array([0.0, 0.3, 0.6])
    np.testing.assert_allclose(expansion_coefficient(s, cos_theta=1.0), (1 - s) ** 2)
    np.testing.assert_allclose(expansion_coefficient(s, cos_theta=0.0), 1 + s**2)
    np.testing.assert_allclose(expansion_coefficient(s, cos_theta=-1.0), (1 + s) ** 2)


def test_turning_cosines_by_hand():
    # pores 0 -> 1 -> {2 (+x), 3 (+y)}, equal flows out of 1: M_1 = (1/2, 1/2, 0)
    centers = np.array([[1, 0, 0], [1, 1, 0], [1, 0, 1],        # face x = 1 (throat 0)
                        [2, 0, 0], [2, 1, 0], [2, 0, 1],        # face x = 2 (throat 1)
                        [0, 2, 0], [1, 2, 0], [0, 2, 1.0]])     # face y = 2 (throat 2)
    verts = np.array([[0, 1, 2], [3, 4, 5], [6, 7, 8]])
    xyz = np.array([[0.5, 0.3, 0.3], [1.5, 0.5, 0.3], [2.5, 0.3, 0.3], [1.5, 2.5, 0.3]])
    conns = np.array([[0, 1], [1, 2], [1, 3]])
    cos = turning_cosines(centers, verts, xyz, conns, [2.0, 1.0, 1.0], axis=0)
    np.testing.assert_allclose(cos[:, 0], [0.5, 1.0, 0.0], atol=1e-12)   # outlets: the axis
    np.testing.assert_allclose(cos[0, 1], -1.0, atol=1e-12)               # back into 0
    part = turning_cosines(centers, verts, xyz, conns, [2.0, 1.0, 1.0], axis=0, recovery=0.5)
    np.testing.assert_allclose(part, cos + 0.5 * (1 - cos), atol=1e-12)
    with pytest.raises(ValueError, match="recovery"):
        turning_cosines(centers, verts, xyz, conns, [2.0, 1.0, 1.0], axis=0, recovery=1.5)


def test_loss_and_onset_coefficients_on_two_tetrahedra():
    # two tetrahedra sharing face 0 (three spheres r 0.3 at unit spacing); h 0.25 each side
    c = np.array([[0, 0, 0], [1, 0, 0], [0.5, 0.87, 0], [0.5, 0.29, 0.82], [0.5, 0.29, -0.82]])
    tess = tessellate(Packing(c, np.full(5, 0.3)))
    assert tess.throat_pores[0].tolist() == [0, 1]
    h = np.array([[0.25, 0.25]])
    smooth = inertial_coefficients(tess, [0], h, density_kg_m3=1.2)
    aw = throats.open_area(tess.throat_radii[:1], tess.throat_sides[:1])[0]
    rk = np.sqrt(0.3**2 - 0.25**2)
    sigma = aw / throats.open_area(np.full((1, 3), rk), tess.throat_sides[:1])[0]
    # Borda-Carnot over the window: no contraction loss at a sphere-rounded window
    np.testing.assert_allclose(smooth, 1.2 / (2 * aw**2) * (1 - sigma) ** 2, rtol=1e-12)
    # c |q| = Re_w / Re_c, Re_w = rho |q| D_w / (mu A_w), Re_c = k_inf a / (c_1 h)
    cs = onset_scales(tess, [0], h, smooth, slope=0.1, density_kg_m3=1.2, viscosity_pa_s=2e-5)
    re_per_q = 1.2 * 2 * np.sqrt(aw / np.pi) / (2e-5 * aw)
    re_c = (1 - sigma) ** 2 * 0.3 / (0.1 * 0.25)
    np.testing.assert_allclose(cs, re_per_q / re_c, rtol=1e-12)
    with pytest.raises(ValueError, match="slope must be finite and > 0"):
        onset_scales(tess, [0], h, smooth, slope=0.0)
