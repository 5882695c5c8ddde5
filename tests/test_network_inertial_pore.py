"""The conduit laws from a resolved 3-D pore body (``PORE_LAW``, and ``CHAIN_LAW``, the CLI's
default: the same body in a chain; issue 14; docs/inertial-flow.md).

Pore table: steady 3-D Navier-Stokes through a regular tetrahedral pore (spheres r 0.9 at the
vertices of a tetrahedron of edge 2; ``docs/scripts/inertial_pore_ns.py``): the body's excess
loss coefficient k_body at window Reynolds numbers 1-200 for 'pore', and k_body with the
outflow's kinetic energy k_out for 'chain', from the finest mesh of session 9's corrected series
(outlet windows fully open; docs/inertial-flow.md, "The pore table corrected"). LBM reference:
``docs/scripts/lbm_periodic.py`` on the periodic packing phi 0.60, n 30, seed 1 at 28 lattice
units per diameter (docs/inertial-lbm.md), an independent resolved computation of the very
packing the network is built on; and the same script on a GPU for the n = 800 validation
packings themselves and an FCC array (docs/data/lbm_n800_reference.json,
lbm_arrays_reference.json), which did not exist when the chained law's recipe was written
(docs/inertial-flow.md, "Order of work").
"""

import numpy as np
import pytest

from network.conductance import (CHAIN_ONSET_SLOPE, CHAIN_RECOVERY, PORE_ONSET_SLOPE,
                                 PORE_RECOVERY, conduit_law, expansion_coefficient,
                                 inertial_coefficients)
from network.flow import INERTIAL_LAWS
from network.packing import random_packing
from network.pores import tessellate
from network.validation import (CHAIN_LAW, DERIVED_LAW, PORE_LAW, lattice_inertial_case,
                                random_inertial_case)

PORE_RE = np.array([1, 5, 10, 20, 50, 100, 200], dtype=float)
PORE_K_BODY = np.array([0.16268, 0.26898, 0.39773, 0.56481, 0.59493, 0.45438, 0.29099])
#: The chained law's table: the same run's k_body and k_out, the kinetic energy the outflow
#: carries through the three outlet windows over a flat profile (per rho u_w^2 Q/2)
CHAIN_K_BODY = PORE_K_BODY
CHAIN_K_OUT = np.array([0.22793, 0.20537, 0.20253, 0.24920, 0.43552, 0.64169, 0.81336])
PORE_SIGMA, PORE_COS, PORE_H_OVER_A = 0.63715, 1.0 / 3.0, 1.0 / np.sqrt(6) / 0.9

#: LBM k/k_app (phi 0.60, n 30, seed 1, D 28) at its Reynolds numbers
LBM_RE = np.array([1.00, 4.88, 9.68, 19.43])
LBM_RATIO = np.array([1.0027, 1.0483, 1.1247, 1.2916])


def _onset_fit(k):
    """(k_peak, Re_c from the Re_w 5 and 10 rows) of k = k_peak t/sqrt(1+t^2), t = Re_w/Re_c."""
    peak = k.max()
    x = k[1:3] / peak
    return peak, PORE_RE[1:3] / (x / np.sqrt(1 - x * x))


def test_pore_constants_come_from_the_pore_table():
    # k = k_peak t/sqrt(1+t^2), t = Re_w/Re_c: Re_c from the Re_w 5 and 10 rows, slope
    # k_peak/Re_c = c_1 h/a
    peak, re_c = _onset_fit(PORE_K_BODY)
    np.testing.assert_allclose(re_c, 10.49, rtol=0.07)      # 9.86 and 11.12
    assert re_c.mean() == pytest.approx(10.49, rel=0.001)
    assert peak / (re_c.mean() * PORE_H_OVER_A) == pytest.approx(PORE_ONSET_SLOPE, rel=0.01)
    # the turning balance with the recovered share f gives the body's peak loss
    cos = PORE_COS + PORE_RECOVERY * (1 - PORE_COS)
    assert float(expansion_coefficient(PORE_SIGMA, cos_theta=cos)) == pytest.approx(peak,
                                                                                     rel=0.002)
    # the form holds over the pore's rise (Re_w 5-50) within 0.1 of the peak
    t = PORE_RE / re_c.mean()
    rise = (PORE_RE >= 5) & (PORE_RE <= 50)
    np.testing.assert_allclose((PORE_K_BODY / peak)[rise], (t / np.sqrt(1 + t * t))[rise],
                               atol=0.1)


def test_chain_constants_come_from_the_pore_table():
    # the next body dissipates what the jets carry out beyond their Re_w 5 share; the same
    # recipe as the pore's constants on k_chain = k_body + k_out - k_out(5)
    chain = CHAIN_K_BODY + CHAIN_K_OUT - CHAIN_K_OUT[1]
    assert np.all(np.diff(chain) > 0)                 # keeps rising: no peak at Re_w 50
    peak, re_c = _onset_fit(chain)
    assert peak == pytest.approx(0.8990, abs=1e-4)
    np.testing.assert_allclose(re_c, [15.95, 20.45], rtol=2e-3)
    assert peak / (re_c.mean() * PORE_H_OVER_A) == pytest.approx(CHAIN_ONSET_SLOPE, rel=0.002)
    cos = PORE_COS + CHAIN_RECOVERY * (1 - PORE_COS)
    assert float(expansion_coefficient(PORE_SIGMA, cos_theta=cos)) == pytest.approx(peak,
                                                                                     rel=0.002)
    # the form holds from Re_w 5 to 200 within 0.065 of the peak (0.063 at Re_w 20; 0.049 on
    # session 8's faulty table)
    t = PORE_RE / re_c.mean()
    np.testing.assert_allclose((chain / peak)[1:], (t / np.sqrt(1 + t * t))[1:], atol=0.065)
    assert CHAIN_LAW == {**DERIVED_LAW, "recovery": CHAIN_RECOVERY,
                         "onset_slope": CHAIN_ONSET_SLOPE}


# the recorded network ratios below moved by up to 4e-4 when every table lookup came to read
# a throat in one vertex order (cache/_order.py, session 21); the comparisons kept their margins
#: LBM k/k_app of the n = 800 phi 0.60 seed 1 validation packing (D 56, GPU, session 8)
LBM800_RE = np.array([4.8706, 9.6214, 19.2959, 47.7126])
LBM800_RATIO = np.array([1.0497, 1.1313, 1.3008, 1.7935])


def _against_lbm(phi, seed, re, lbm, law, recorded, rtol):
    """Relative error of the n = 800 network's k/k_app against the LBM's, after checking the
    network converged and reproduces its ``recorded`` ratios."""
    case = random_inertial_case(phi, re, n_spheres=800, rng=seed, **law)
    assert case.converged
    np.testing.assert_allclose(case.k_ratio, recorded, rtol=rtol)
    return case.k_ratio / lbm - 1


def test_chain_law_follows_the_lbm_of_the_n800_packing():
    # recorded with session 9's corrected constants
    err = _against_lbm(0.60, 1, LBM800_RE, LBM800_RATIO, CHAIN_LAW,
                       [1.05764, 1.14434, 1.32238, 1.80426], 2e-4)
    assert np.all(np.abs(err[:2]) < 0.012)       # 1.2 % of the LBM to Re_p 10 (+0.8, +1.1 %)
    assert np.all(np.abs(err[2:]) < 0.06)        # and 6 % at Re_p 20 and 50 (+1.6, +0.6 %)
    # the single pore ('pore', session 7's default) is 12 % low at Re_p 50
    old = random_inertial_case(0.60, LBM800_RE[3:], n_spheres=800, rng=1, **PORE_LAW)
    assert old.k_ratio[0] / LBM800_RATIO[3] - 1 == pytest.approx(-0.115, abs=0.005)


#: LBM k/k_app of the FCC array, phi 0.60, flow along a cube axis (D 56, GPU, session 8)
FCC_RE = np.array([5.0148, 10.2163, 21.2117, 57.7158])
FCC_RATIO = np.array([1.0195, 1.0654, 1.1834, 1.4826])


def test_chain_law_follows_the_lbm_of_the_fcc_array():
    case = lattice_inertial_case("fcc", 0.60, FCC_RE, **CHAIN_LAW)
    assert case.converged
    np.testing.assert_allclose(case.k_ratio, [1.01759, 1.05680, 1.15332, 1.46860], rtol=2e-4)
    err = case.k_ratio / FCC_RATIO - 1
    assert np.all(np.abs(err[:2]) < 0.02)         # 2 % to Re_p 10 (-0.2, -0.8 %)
    assert np.all(np.abs(err[2:]) < 0.05)         # 5 % to Re_p 58 (-2.5, -0.9 %)


def test_pore_law_follows_the_lbm_of_the_same_packing():
    # Re_p 0.25 and 0.5 for the weak-inertia onset, then the LBM's own Reynolds numbers
    case = random_inertial_case(0.60, np.r_[0.25, 0.5, LBM_RE], n_spheres=30, rng=1,
                                **PORE_LAW)
    assert case.converged
    excess = case.k_ratio[:2] - 1
    assert excess[1] / excess[0] == pytest.approx(4.0, rel=0.05)     # Re^2 onset
    ratio = case.k_ratio[2:]
    # recorded with session 9's corrected constants
    np.testing.assert_allclose(ratio, [1.00430, 1.05269, 1.12136, 1.25418], rtol=2e-4)
    err = ratio / LBM_RATIO - 1
    assert np.all(np.abs(err[:3]) < 0.02)        # within 2 % of the resolved flow to Re_p 10
    assert abs(err[3]) < 0.06                    # within 6 % at Re_p 20 (-3.0 %)
    # the single-constriction slope (DERIVED_LAW) is 5 % low at Re_p 10 on the same packing
    old = random_inertial_case(0.60, LBM_RE[2:3], n_spheres=30, rng=1, **DERIVED_LAW)
    assert old.k_ratio[0] / LBM_RATIO[2] - 1 == pytest.approx(-0.052, abs=0.005)


def test_conduit_law_matches_the_separate_steps():
    pk = random_packing(60, rng=2, periodic=False, solid_fraction=0.50)
    tess = tessellate(pk)
    idx = np.arange(np.asarray(tess.throat_pores).shape[0])
    h = np.full((idx.size, 2), 1e-3)
    K, c, xc = conduit_law(tess, idx, h, profile="laminar", crossover=1.0)
    np.testing.assert_array_equal(K, inertial_coefficients(tess, idx, h, profile="laminar"))
    assert c is None and xc == 1.0
    with pytest.raises(ValueError, match="turning needs"):
        conduit_law(tess, idx, h, turning=True)
    with pytest.raises(ValueError, match="onset must be"):
        conduit_law(tess, idx, h, onset="body")
    # 'pore' and the default 'chain' are the derived form with the pore's two constants
    assert INERTIAL_LAWS["pore"] == PORE_LAW == {**DERIVED_LAW, "recovery": PORE_RECOVERY,
                                                "onset_slope": PORE_ONSET_SLOPE}
    assert INERTIAL_LAWS["chain"] == CHAIN_LAW


def test_cli_json_names_the_law(tmp_path):
    # the default law changed in session 7 ('onset' -> 'pore'), 8 (-> 'chain') and 11 (->
    # 'window'): every JSON says which it used
    import json

    from network import curve, solve

    for law, args in (("window", []), ("chain", ["--inertial-law", "chain"]),
                      ("pore", ["--inertial-law", "pore"]),
                      ("onset", ["--inertial-law", "onset"])):
        out = tmp_path / f"s_{law}.json"
        assert solve.main(["-q", "--json", str(out)] + args) == 0
        assert json.loads(out.read_text())["inertial_law"] == law
    out = tmp_path / "c.json"
    assert curve.main(["-q", "--velocities", "0.01,0.1", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["inertial_law"] == "window"


def _window_row(rows, r):
    """(sigma, c_1, f) of the chained law's recipe on one pore's rows (Re_w 0 row first)."""
    geo = rows[0]
    by = {row["Re_w"]: row for row in rows[1:]}
    k_body = np.array([by[re]["k_body"] for re in PORE_RE])
    k_out = np.array([by[re]["k_out"] for re in PORE_RE])
    peak, re_c = _onset_fit(k_body + k_out - k_out[1])
    c1 = peak / (re_c.mean() * np.sqrt(2.0 / 3.0) / 2.0 / r)     # h/a = (L sqrt(2/3)/4)/r, L 2
    cos = (1 + geo["sigma"] ** 2 - peak) / (2 * geo["sigma"])    # the turning balance = peak
    return geo["sigma"], c1, (cos - geo["cos_theta"]) / (1 - geo["cos_theta"])


def test_window_table_comes_from_the_pore_rows():
    # every row of CHAIN_WINDOW_TABLE is the chained recipe on the stored Navier-Stokes rows of
    # one pore radius (its h 0.10 run, the finest graded one where several), and r 0.90's row
    # is the 'chain' constants
    import json
    from pathlib import Path

    from network.conductance import CHAIN_WINDOW_TABLE, window_constants

    data = json.loads((Path(__file__).parents[1] / "docs" / "data"
                       / "pore_ns_series.json").read_text())
    runs = {0.90: data["corrected"]["h0.10_n8"]}
    runs |= {float(k[1:]): v for k, v in data["radii"].items()}
    runs |= {float(k[1:]): v for k, v in data["radii_across6"].items()}
    rows = sorted((_window_row(v, r) for r, v in runs.items()), key=lambda x: x[0])
    sigma, c1, f = (np.array(x) for x in zip(*rows))
    np.testing.assert_allclose(CHAIN_WINDOW_TABLE["sigma"], sigma, atol=1e-4)
    np.testing.assert_allclose(CHAIN_WINDOW_TABLE["onset_slope"], c1, atol=1e-4)
    np.testing.assert_allclose(CHAIN_WINDOW_TABLE["recovery"], f, atol=1e-3)
    assert window_constants(PORE_SIGMA)[0] == pytest.approx(CHAIN_ONSET_SLOPE, abs=1e-4)
    assert window_constants(PORE_SIGMA)[1] == pytest.approx(CHAIN_RECOVERY, abs=1e-3)
    # linear between rows, the end rows held outside
    mid = 0.5 * (sigma[0] + sigma[1])
    assert window_constants(mid)[1] == pytest.approx(0.5 * (f[0] + f[1]), abs=1e-3)
    np.testing.assert_allclose(window_constants([0.1, 0.99])[1], [f[0], f[-1]], atol=1e-3)


def _interior_law_inputs(n, packing_seed, solid_fraction, seed, *, axis):
    """A small random packing's interior throats with random heights (m), pore positions and
    Stokes flows: ``(tessellation, throat indices, h, conduit_law keywords)``."""
    pk = random_packing(n, rng=packing_seed, periodic=False, solid_fraction=solid_fraction)
    tess = tessellate(pk)
    idx = np.flatnonzero(np.all(np.asarray(tess.throat_pores) >= 0, axis=1))
    rng = np.random.default_rng(seed)
    h = rng.uniform(0.2, 0.5, (idx.size, 2)) * 1e-3
    conns = np.asarray(tess.throat_pores)[idx]
    xyz = rng.normal(size=(conns.max() + 1, 3))
    q = rng.normal(size=idx.size)
    return tess, idx, h, dict(pore_xyz_m=xyz, conns=conns, stokes_flow_m3_s=q, axis=axis)


def test_window_law_with_one_row_is_the_chain_law(monkeypatch):
    # a table whose every row holds the 'chain' constants gives the 'chain' law exactly: the
    # per-conduit path changes nothing but where the constants come from
    from network.conductance import _inertial as inertial

    tess, idx, h, common = _interior_law_inputs(60, 2, 0.50, 3, axis=0)
    flat = {"sigma": (0.3, 0.9), "onset_slope": (CHAIN_ONSET_SLOPE,) * 2,
            "recovery": (CHAIN_RECOVERY,) * 2}
    monkeypatch.setattr(inertial, "CHAIN_WINDOW_TABLE", flat)
    K1, c1, _ = conduit_law(tess, idx, h, **common, **{**CHAIN_LAW, "recovery": "window",
                                                       "onset_slope": "window"})
    K0, c0, _ = conduit_law(tess, idx, h, **common, **CHAIN_LAW)
    np.testing.assert_allclose(K1, K0, rtol=1e-13)
    np.testing.assert_allclose(c1, c0, rtol=1e-13)
    with pytest.raises(ValueError, match="recovery must be a number or 'window'"):
        conduit_law(tess, idx, h, **common, **{**CHAIN_LAW, "recovery": "sigma"})


def test_conduit_law_threads_change_no_bit():
    """The body sections' areas and the turning cosines on threads: the same K and onset."""
    tess, idx, h, common = _interior_law_inputs(80, 4, 0.55, 5, axis=2)
    for law in ({**CHAIN_LAW, "recovery": "window", "onset_slope": "window"}, CHAIN_LAW):
        K1, c1, _ = conduit_law(tess, idx, h, **common, **law)
        K2, c2, _ = conduit_law(tess, idx, h, **common, **law, threads=2)
        assert np.array_equal(K1, K2) and np.array_equal(c1, c2)
        assert np.isfinite(K1).all() and (K1 >= 0).all()


#: LBM k/k_app of a packing run after the window table was fixed (phi 0.55, n 800, seed 3,
#: D 40, GPU, session 10; docs/data/lbm_n800_reference.json)
LBM_FRESH_RE = np.array([4.8366, 9.5617, 19.0943, 47.0578])
LBM_FRESH_RATIO = np.array([1.0620, 1.1487, 1.3286, 1.8405])


def test_window_law_on_a_fresh_loose_packing():
    from network.validation import WINDOW_LAW

    err = _against_lbm(0.55, 3, LBM_FRESH_RE, LBM_FRESH_RATIO, WINDOW_LAW,
                       [1.06941, 1.16737, 1.36593, 1.91284], 3e-4)
    # +0.7 / +1.6 / +2.8 / +3.9 %: inside issue 14's 2 % at Re_p 10 and 6 % at Re_p 50 with the
    # table extended to sigma 0.837 (session 11; the seven-row table of session 10 gave +1.3 /
    # +2.5 / +4.2 / +5.9 %, 'chain' +1.6 / +3.3 / +5.0 / +6.0 % on the same packing)
    assert np.all(err > 0) and err[0] < 0.008 and err[1] < 0.02 and err[3] < 0.045


#: LBM k/k_app of a packing run and compared only after the nine-row window table was fixed
#: (phi 0.55, n 800, seed 4, D 40, GPU, session 11; docs/data/lbm_n800_reference.json)
LBM_BLIND_RE = np.array([4.8411, 9.5762, 19.1364, 47.2933])
LBM_BLIND_RATIO = np.array([1.06102, 1.14699, 1.32572, 1.83132])


def test_default_law_on_a_blind_loose_packing():
    # the default law (window) on a packing it was never compared with before its table was
    # fixed: +0.7 / +1.6 / +2.6 / +4.0 % of the resolved flow, issue 14's 2 % at Re_p <= 10 and
    # 6 % at Re_p 50; 'chain' on the same packing +1.7 / +3.3 / +4.9 / +6.2 %
    from network.flow import DEFAULT_INERTIAL_LAW, INERTIAL_LAWS

    assert DEFAULT_INERTIAL_LAW == "window"
    err = _against_lbm(0.55, 4, LBM_BLIND_RE, LBM_BLIND_RATIO,
                       INERTIAL_LAWS[DEFAULT_INERTIAL_LAW], [1.06866, 1.16496, 1.36098, 1.90502],
                       3e-4)
    assert np.all(err > 0) and np.all(err[:2] < 0.02) and err[3] < 0.06


#: LBM k/k_app of phi 0.60 seed 1 at the highest Re_p resolved (n 800, D 72, GPU, session 17;
#: 0.26 % above D 56 at equal Re; docs/data/lbm_n800_reference.json)
LBM_HIGH_RE = np.array([86.8149])
LBM_HIGH_RATIO = np.array([2.44623])


def test_default_law_near_re_100():
    # how far towards Re_p 200 the network holds against the resolved flow: +0.7 % at Re_p 87
    # ('chain' -1.0 %); above Re_p 100 nothing resolved is at hand (docs/inertial-lbm.md)
    from network.flow import DEFAULT_INERTIAL_LAW, INERTIAL_LAWS

    err = _against_lbm(0.60, 1, LBM_HIGH_RE, LBM_HIGH_RATIO,
                       INERTIAL_LAWS[DEFAULT_INERTIAL_LAW], [2.46548], 3e-4)
    assert 0.0 < err[0] < 0.015
    err_chain = _against_lbm(0.60, 1, LBM_HIGH_RE, LBM_HIGH_RATIO, CHAIN_LAW, [2.42225], 3e-4)
    assert -0.015 < err_chain[0] < 0.0
