"""Size spread of multi-sphere grains: each grain is its template scaled by
f = 1 + cv z (z standard normal cut at 2.5); cv = 0 is the packing without spread, bit for bit."""

import json

import numpy as np
import pytest

from dem import pack
from dem._clump_pack import SIZE_CUT, _mean_cube, pack_grains
from dem import Container
from dem.templates import library_template

BOX = Container("box", (0.03, 0.03), 0.03)
FAST = dict(grow_steps=400, sediment_steps=200, max_steps=400, rng=3)


@pytest.fixture(scope="module")
def soybean():
    return library_template("soybean")


def test_mean_cube_of_the_cut_normal():
    # E[(1 + c z)^3] = 1 + 3 c^2 E[z^2] (odd moments vanish); E[z^2] of the normal cut at 2.5:
    # 1 - 2 a phi(a) / (2 Phi(a) - 1) = 0.91132 (a = 2.5)
    a = SIZE_CUT
    phi = np.exp(-a * a / 2) / np.sqrt(2 * np.pi)
    from math import erf
    var = 1 - 2 * a * phi / erf(a / np.sqrt(2))
    assert _mean_cube(0.1) == pytest.approx(1 + 3 * 0.01 * var, rel=1e-6)
    assert _mean_cube(0.0) == 1.0


def test_zero_spread_is_the_packing_without_spread(soybean):
    a = pack_grains(BOX, soybean, n_grains=12, **FAST)
    b = pack_grains(BOX, soybean, n_grains=12, size_cv=0.0, **FAST)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    assert b[4]["size_cv"] == 0.0 and b[4]["grain_scale_range"] == [1.0, 1.0]


def test_grains_are_whole_templates_scaled_by_their_own_factor(soybean):
    xs, r, gid, grains, summary = pack_grains(BOX, soybean, n_grains=60, size_cv=0.1, **FAST)
    r0 = soybean.radii
    f = np.array([np.mean(r[gid == g] / r0) for g in range(60)])
    for g in range(60):                                    # every sphere of a grain: one factor
        np.testing.assert_allclose(r[gid == g], f[g] * r0, rtol=1e-12)
    assert np.all(np.abs(f - 1) <= SIZE_CUT * 0.1 + 1e-12)
    assert 0.07 < np.std(f, ddof=1) < 0.13                 # cv 0.1 from 60 draws (+-0.009 1 sigma)
    np.testing.assert_allclose(grains["volume_m3"], soybean.volume_m3 * f**3, rtol=1e-12)
    assert summary["grain_scale_range"] == [pytest.approx(f.min()), pytest.approx(f.max())]


def test_grain_count_from_the_mean_volume(soybean):
    # the porosity sets N = floor((1 - phi) V / (V_t E[f^3])): fewer grains with a spread
    v = BOX.volume_m3
    n0 = int(0.6 * v / soybean.volume_m3)
    n1 = int(0.6 * v / (soybean.volume_m3 * _mean_cube(0.2)))
    assert n1 < n0
    out = pack_grains(BOX, soybean, porosity=0.4, size_cv=0.2, grow_steps=2, sediment_steps=2,
                      max_steps=2, rng=1)
    assert out[4]["n_grains"] == n1


@pytest.mark.parametrize("cv", [-0.1, 0.3, float("nan")])
def test_bad_spread_is_refused(soybean, cv):
    with pytest.raises(ValueError, match="size spread"):
        pack_grains(BOX, soybean, n_grains=4, size_cv=cv, **FAST)


def test_cli_bad_spread_exit_2_and_library_default_stated(tmp_path, capsys):
    out = tmp_path / "b.csv"
    code = pack.main(["--scene", "box", "--size", "0.03", "0.03", "--height", "0.03", "--grain", "soybean",
                      "--size-cv", "0.5", "--out", str(out), "--quiet"])
    assert code == 2 and "size spread" in capsys.readouterr().err and not out.exists()
    code = pack.main(["--scene", "box", "--size", "0.03", "0.03", "--height", "0.03", "--grain", "soybean",
                      "--fill", "grow", "--n-grains", "8", "--max-steps", "300", "--out", str(out), "--quiet"])
    summary = json.loads(out.with_suffix(".json").read_text())
    assert summary["size_cv"] == 0.0 and "no axis standard deviations" in summary["size_cv_source"]
