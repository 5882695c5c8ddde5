"""CLIs: python -m network.solve / network.throatlist on the bundled scene."""

import json

import numpy as np
import pytest

from network import default_packing_path, read_packing, tessellate
from network import solve as solve_cli
from network import throatlist as throats_cli
from network.flow import read_vtu_arrays

KEYS = ["permeability_m2", "pressure_drop_pa", "pressure_gradient_pa_per_m", "porosity",
        "n_pores", "n_throats", "seconds", "comparisons", "conductance_model", "k_over_d2"]


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("solve")
    rc = solve_cli.main(["--policy", "shape-factor", "--json", str(d / "o.json"),
                         "--vtk", str(d / "o.vtu"), "-q"])
    return rc, json.loads((d / "o.json").read_text()), read_vtu_arrays(d / "o.vtu")


@pytest.mark.slow
def test_bundled_scene_is_soybean_like():
    pk = read_packing(default_packing_path())
    d = 2 * pk.radii
    assert 2000 <= pk.n <= 4000
    assert d.min() >= 5.5e-3 - 1e-8 and d.max() <= 7.5e-3 + 1e-8
    assert default_packing_path().stat().st_size <= 200_000


@pytest.mark.slow
def test_solve_default_scene(default_run, capsys):
    rc, out, vtu = default_run
    assert rc == 0
    for k in KEYS:
        assert k in out, k
    assert out["conductance_model"] == "conduit" and out["policy"] == "shape-factor"
    # the conduit's pore merge is summarised as numbers, not an object's repr
    assert out["qstar"]["merge"]["n_groups"] < out["n_pores"] + out["n_dropped_pores"] + 10**6
    assert isinstance(out["qstar"]["merge"]["n_groups"], int)
    # porosity of the interior box of the bundled scene (data/README.md: 0.399 +- 0.001), and
    # of its inset window, where k is measured (0.394)
    assert abs(out["porosity_sample"] - 0.399) < 0.004 and abs(out["porosity"] - 0.394) < 0.004
    assert out["mass_balance"]["ok"] and out["mass_balance"]["balance_error"] < 1e-8
    # the reported numbers are consistent with Darcy's law
    k, mu, v = out["permeability_m2"], out["viscosity_pa_s"], out["velocity_m_s"]
    assert np.isclose(out["pressure_gradient_stokes_pa_per_m"], mu * v / k)
    assert np.isclose(out["pressure_drop_stokes_pa"], 0.25 * mu * v / k)
    assert out["pressure_drop_pa"] > out["pressure_drop_stokes_pa"]        # inertia
    # ASABE D272 soybeans at 0.013 m/s over 0.25 m: 2.28 Pa (thesis 4.2.3)
    assert round(out["comparisons"]["asabe_d272"]["pressure_drop_pa"], 2) == 2.28
    assert vtu["pressure"].shape == (out["n_pores"],)
    assert vtu["flow"].shape == vtu["conductance"].shape == (out["n_throats"],)
    assert vtu["Points"].shape == (out["n_pores"], 3)
    # pressures of the flow-imposed Stokes problem (the .vtu holds the Stokes field: v over the
    # whole cross-section) span mu v H / k_whole
    dp = vtu["pressure"].max() - vtu["pressure"].min()
    assert np.isclose(dp, mu * v * out["sample_length_m"] / out["permeability_whole_m2"],
                      rtol=1e-9)
    assert out["sample_estimator"] == "inset"
    assert abs(out["permeability_m2"] / out["permeability_whole_m2"] - 1) < 0.05


@pytest.mark.slow
def test_solve_all_axes(tmp_path):
    rc = solve_cli.main(["--axis", "all", "--policy", "shape-factor", "-q",
                         "--json", str(tmp_path / "a.json")])
    out = json.loads((tmp_path / "a.json").read_text())
    assert rc == 0 and set(out["by_axis"]) == {"x", "y", "z"}
    ks = [out["by_axis"][a]["permeability_m2"] for a in "xyz"]
    assert np.isclose(out["permeability_m2"], np.mean(ks))
    # the top-level gradient is Stokes at the mean k, and says so; each axis's is inertial
    assert out["pressure_gradient_pa_per_m"] == 1.932e-5 * 0.013 / out["permeability_m2"]
    assert out["pressure_gradient_note"] == ("Stokes, mu v / the mean k; each axis's value with "
                                             "inertia is under by_axis")
    for a in "xyz":
        b = out["by_axis"][a]
        assert b["pressure_gradient_pa_per_m"] > b["pressure_gradient_stokes_pa_per_m"]
    # a geometric packing without gravity is statistically isotropic: within 15 %
    assert max(ks) / min(ks) < 1.15


@pytest.mark.slow
def test_solve_bad_file(tmp_path, capsys):
    p = tmp_path / "bad.csv"
    p.write_text("x,y,z,r\n1,2,3\n")
    assert solve_cli.main([str(p), "-q"]) == 2
    assert "row 2" in capsys.readouterr().err
    assert solve_cli.main([str(tmp_path / "missing.csv"), "-q"]) == 2


@pytest.mark.slow
def test_throats_export(tmp_path):
    out = tmp_path / "t.csv"
    assert throats_cli.main(["--out", str(out), "-q"]) == 0
    header = out.read_text().splitlines()[0]
    assert header == "r1,r2,r3,l12,l13,l23,throat,pore1,pore2"
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    t = tessellate(read_packing(default_packing_path()))
    idx = data[:, 6].astype(int)
    assert np.unique(idx).size == idx.size                     # every throat once
    np.testing.assert_allclose(data[:, :3], t.throat_radii[idx], rtol=1e-8)
    np.testing.assert_allclose(data[:, 3:6], t.throat_sides[idx], rtol=1e-8)
    assert np.all(data[:, 8] >= 0)                              # interior faces only
