"""network.bin: the bin's Darcy-Forchheimer solve against closed forms and the report's 1-D
system curve, its mass balance, the tensor law, and the command's contract."""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest

from network.report.system import system_rows
from network.bin import (BinGeometry, BinProblem, ForchheimerLaw, PorosityProfile, SheddLaw,
                         closed_form_radial_airflow, d272_material, mesh_bin, mesh_rz_polygon,
                         network_material)
from network.bin.__main__ import main
from network.bin._geometry import default_size

MU, RHO = 1.932e-5, 1.20


@pytest.fixture(scope="module")
def wheat():
    return network_material("wheat", viscosity_pa_s=MU, density_kg_m3=RHO)


def _solve(geom, material, pressure, elements=3000):
    prob = BinProblem(mesh_bin(geom, default_size(geom, elements)), material,
                      geom.surface_height)
    return prob, prob.solve(pressure)


# ------------------------------------------------------------------ the law
@pytest.mark.parametrize("law", [ForchheimerLaw(np.array([3.0]), np.array([40.0]), 0.6),
                                 SheddLaw(np.array([1.3]), 2.7e4, 8.77, 0.6)])
def test_the_tensor_law_inverts_and_reduces_to_the_directional_laws(law):
    """u = -M(G) A g satisfies g = -(F(W)/W) A^-1 u with W = |A^-1/2 u|; along z it is the
    vertical law F(U), along x the horizontal law F(U/sqrt a)/sqrt a."""
    a = law.anisotropy
    A = np.array([a, a, 1.0])
    rng = np.random.default_rng(3)
    g = rng.normal(size=(3, 50)) * 200.0
    G = np.sqrt(np.sum(g * A[:, None] * g, axis=0))
    w, _ = law.speed(G)
    u = -(w / G) * A[:, None] * g
    W = np.sqrt(np.sum(u * u / A[:, None], axis=0))
    assert np.allclose(W, w, rtol=1e-12)
    back = -(law.resistance(W) / W) * u / A[:, None]
    assert np.allclose(back, g, rtol=1e-11)
    U = 0.07
    gz = law.resistance(np.array([U]))[0]
    wz, _ = law.speed(np.array([gz]))
    assert wz[0] == pytest.approx(U, rel=1e-12)
    gx = law.resistance(np.array([U / np.sqrt(a)]))[0] / np.sqrt(a)   # horizontal gradient
    wx, _ = law.speed(np.array([np.sqrt(a) * gx]))                    # G = sqrt(a) |g_x|
    assert a * gx * (wx[0] / (np.sqrt(a) * gx)) == pytest.approx(U, rel=1e-12)


def test_the_forchheimer_tensor_law_gives_beta_h_from_the_scaling():
    """Horizontal flow: g = mu U/k_h + beta_h rho U^2 with k_h = a k_v, beta_h = beta_v a^-1.5."""
    mu, k, beta, rho, a = 1.8e-5, 1e-8, 4000.0, 1.2, 1.7
    law = ForchheimerLaw(np.array([mu / k]), np.array([beta * rho]), a)
    U = 0.2
    gx = mu * U / (a * k) + beta * a**-1.5 * rho * U**2
    w, _ = law.speed(np.array([np.sqrt(a) * gx]))
    assert a * w[0] / np.sqrt(a) == pytest.approx(U, rel=1e-12)


def test_the_newton_matrix_is_the_derivative_of_the_residual(wheat):
    """J dp matches the central difference of R (the symmetric form of the module)."""
    geom = BinGeometry(4.0, 2.0, "peaked", 25.0)
    prob = BinProblem(mesh_bin(geom, 0.25), wheat, geom.surface_height)
    rng = np.random.default_rng(7)
    p = 300.0 * rng.random(prob.skmesh.p.shape[1])
    dp = rng.normal(size=p.size)
    J = prob.jacobian(p)
    h = 1e-4
    fd = (prob.residual(p + h * dp) - prob.residual(p - h * dp)) / (2 * h)
    assert np.allclose(J @ dp, fd, rtol=1e-6, atol=1e-9 * np.abs(fd).max())
    assert abs(J - J.T).max() <= 1e-12 * abs(J).max()


# ------------------------------------------------------------------ validation (a), (b), (d)
@pytest.mark.parametrize("law", ["network", "d272"])
def test_a_flat_bed_on_a_full_floor_is_the_reports_system_curve(law):
    """(a): the bin's airflow at each fan pressure is the report's 1-D system curve
    (network.report.system.system_rows at the same law and porosity), to the solver's
    tolerance."""
    make = network_material if law == "network" else d272_material
    mat = make("wheat", viscosity_pa_s=MU, density_kg_m3=RHO)
    geom = BinGeometry(6.0, 4.0)
    prob = BinProblem(mesh_bin(geom, 0.3), mat, geom.surface_height)
    area, eps = np.pi * 9.0, mat.profile(0.0)
    rho_b = mat.particle_density_kg_m3 * (1 - eps)
    p0 = None
    for pressure in (20.0, 150.0, 900.0):
        sol = prob.solve(pressure, p0)
        p0 = sol.p
        u = sol.inflow_m3_s / area
        row = system_rows([u], mat.gradient_1d(np.array([u]), eps), depth_m=4.0,
                          area_m2=area, bulk_density_kg_m3=rho_b)[0]
        assert sol.converged
        assert row["static_pressure_pa"] == pytest.approx(pressure, rel=1e-9)
        assert row["airflow_m3_s"] == pytest.approx(sol.inflow_m3_s, rel=1e-12)


def test_a_bin_mesh_ignores_the_gmsh_options_another_mesher_left():
    """gmsh's options are global to the process: second-order elements, a size factor and a
    coarser size integration left by another mesher (the throats' meshes set all three) leave
    a bin's mesh node for node the same."""
    import gmsh

    geom = BinGeometry(6.0, 4.0)
    alone = mesh_bin(geom, 0.3)
    try:
        for name, value in (("Mesh.ElementOrder", 2), ("Mesh.MeshSizeFactor", 0.5),
                            ("Mesh.LcIntegrationPrecision", 1e-3)):
            gmsh.option.setNumber(name, value)
        after = mesh_bin(geom, 0.3)
    finally:
        gmsh.option.restoreDefaults()
    assert after.cells.shape == alone.cells.shape == (3, alone.n_elements)
    np.testing.assert_array_equal(after.cells, alone.cells)
    np.testing.assert_array_equal(after.points, alone.points)


@pytest.mark.slow
def test_a_flat_bed_with_a_porosity_profile_integrates_the_1d_law(wheat, tmp_path):
    """A denser bed with depth: P = integral of g(U, eps(h)) dh (trapezoid on 20 001 points),
    to the discretisation error of element-wise porosity (1e-4 at this mesh)."""
    prof = PorosityProfile(np.array([0.0, 4.0]), np.array([0.42, 0.38]), "test")
    mat = dataclasses.replace(wheat, profile=prof)
    geom = BinGeometry(6.0, 4.0)
    prob = BinProblem(mesh_bin(geom, 0.05), mat, geom.surface_height)
    sol = prob.solve(300.0)
    u = sol.inflow_m3_s / (np.pi * 9.0)
    h = np.linspace(0, 4.0, 20_001)
    g = mat.gradient_1d(np.full(h.size, u), prof(h))
    assert np.trapezoid(g, h) == pytest.approx(300.0, rel=1e-4)


@pytest.mark.slow
def test_b_radial_flow_from_a_perforated_vertical_duct_is_the_closed_form(wheat):
    """(b): radial flow from a perforated cylinder r0 = 0.15 m to r1 = 3 m (closed top and
    bottom), horizontal law (k_h, beta_h), against the closed-form root: second-order
    convergence and a Richardson extrapolate within 5e-5."""
    r0, r1, length, pressure = 0.15, 3.0, 1.0, 400.0
    e = wheat.profile(0.0)
    a = wheat.anisotropy
    exact = closed_form_radial_airflow(pressure, inner_radius_m=r0, outer_radius_m=r1,
                                       length_m=length, viscosity_pa_s=MU,
                                       permeability_m2=float(wheat.k_v(e)) * a,
                                       beta_per_m=float(wheat.beta_v(e)) * a**-1.5,
                                       density_kg_m3=RHO)
    q = []
    for h in (0.05, 0.025):
        mesh = mesh_rz_polygon([(r0, 0), (r1, 0), (r1, length), (r0, length)],
                               ["closed", "surface", "closed", "plenum"], h)
        prob = BinProblem(mesh, wheat, lambda r: np.full_like(np.asarray(r, float), 50.0))
        sol = prob.solve(pressure)
        assert abs(sol.inflow_m3_s / sol.outflow_m3_s - 1) < 1e-8
        q.append(sol.inflow_m3_s)
    err = [abs(v / exact - 1) for v in q]
    assert err[1] < 1e-3
    assert 3.0 < err[0] / err[1] < 5.0
    assert abs((q[1] + (q[1] - q[0]) / 3) / exact - 1) < 5e-5


@pytest.mark.parametrize("top", ["peaked", "inverted"])
def test_d_plenum_inflow_equals_surface_outflow(wheat, top):
    """(d): mass balance of the assembled fluxes to 1e-8 (a cone top: 2-D flow)."""
    geom = BinGeometry(8.0, 5.0, top, 25.0)
    _, sol = _solve(geom, wheat, 200.0)
    assert sol.converged
    assert abs(sol.inflow_m3_s - sol.outflow_m3_s) / sol.inflow_m3_s < 1e-8


@pytest.mark.slow
def test_a_peaked_top_needs_more_pressure_than_a_flat_one_of_its_eave_depth(wheat):
    """The peak adds grain: less airflow at the same pressure, more than a flat bed as deep as
    the peak's apex."""
    flat = _solve(BinGeometry(8.0, 5.0), wheat, 200.0)[1].inflow_m3_s
    peak = _solve(BinGeometry(8.0, 5.0, "peaked", 25.0), wheat, 200.0)[1].inflow_m3_s
    apex = _solve(BinGeometry(8.0, 5.0 + 4.0 * np.tan(np.radians(25.0))), wheat,
                  200.0)[1].inflow_m3_s
    assert apex < peak < flat


# ------------------------------------------------------------------ the command
@pytest.mark.slow
def test_the_command_reports_pressure_uniformity_and_the_check(tmp_path, capsys):
    out = tmp_path / "b.json"
    code = main(["--diameter", "8", "--depth", "5", "--top", "peaked", "--airflow", "0.1",
                 "m3/min/t", "--json", str(out), "--figure", str(tmp_path / "b.png"), "-q"])
    assert code == 0
    r = json.loads(out.read_text())
    assert r["airflow_m3_per_min_t"] == pytest.approx(0.1, rel=1e-8)
    # the numbers README.md quotes for this command
    assert (round(r["static_pressure_pa"], 1), round(r["airflow_m3_s"], 3),
            round(r["grain_mass_t"], 1)) == (59.3, 0.366, 219.8)
    assert round(100 * r["underaerated_fraction"], 1) == 2.7
    assert 8 <= len(r["system_curve"]) <= 12
    ps = [s["static_pressure_pa"] for s in r["system_curve"]]
    qs = [s["airflow_m3_s"] for s in r["system_curve"]]
    assert np.all(np.diff(ps) > 0) and np.all(np.diff(qs) > 0)
    assert r["mass_balance"]["relative_difference"] < 1e-8
    assert r["mesh"]["refinement_check"]["relative_difference"] < 0.005
    assert 0 < r["underaerated_fraction"] < 0.05
    assert r["geometry"]["peak_angle_deg"] == 34.0 and "EN 1991-4" in r["geometry"][
        "peak_angle_source"]
    assert r["converged"] is True and r["law"] == "network"
    assert (tmp_path / "b.png").stat().st_size > 10_000
    assert "uniformity" in capsys.readouterr().out


@pytest.mark.parametrize("argv, words", [
    (["--diameter", "0", "--depth", "5", "--pressure", "100"], "--diameter"),
    (["--diameter", "8", "--depth", "-1", "--pressure", "100"], "--depth"),
    (["--diameter", "8", "--depth", "5", "--pressure", "0"], "--pressure"),
    (["--diameter", "8", "--depth", "5", "--top", "peaked", "--peak-angle", "90",
      "--pressure", "100"], "--peak-angle"),
    (["--diameter", "8", "--depth", "5", "--floor", "duct", "--duct", "0.6", "5", "3.8",
      "--pressure", "100"], "outside the floor"),
    (["--diameter", "8", "--depth", "5", "--floor", "duct", "--duct", "0.6", "9", "0",
      "--pressure", "100"], "longer than the bin"),
    (["--diameter", "8", "--depth", "5", "--airflow", "0.1", "cfs"], "--airflow unit"),
])
def test_bad_input_is_one_error_line_and_exit_2(argv, words, capsys, tmp_path):
    code = main(argv + ["--no-figure", "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("error:") and words in err[0]


def test_a_fan_that_never_crosses_the_bin_is_exit_1_with_both_ranges(tmp_path, capsys):
    fan = tmp_path / "fan.csv"
    fan.write_text("airflow_m3_s,static_pressure_pa\n50,2\n60,1\n")
    code = main(["--diameter", "6", "--depth", "3", "--fan", str(fan), "--no-figure",
                 "--elements", "1500", "--no-refinement-check", "-q"])
    err = capsys.readouterr().err
    assert code == 1
    assert "system curve: airflow" in err and "fan: airflow" in err


@pytest.mark.slow
@pytest.mark.parametrize("shape", ["half-round", "round"])
def test_d_a_floor_duct_in_3d_balances_and_keeps_its_keys(shape, tmp_path):
    """(d) in 3-D: a duct bin (tetrahedra, pyamg-preconditioned CG) balances to 1e-8; the JSON
    has the contract's keys."""
    out = tmp_path / "d.json"
    code = main(["--diameter", "6", "--depth", "3", "--floor", "duct", "--duct", "0.5", "4.5",
                 "1", "--duct-shape", shape, "--pressure", "100", "--elements", "12000",
                 "--json", str(out), "--no-figure", "--no-refinement-check", "-q"])
    assert code == 0
    r = json.loads(out.read_text())
    for key in ("static_pressure_pa", "airflow_m3_s", "airflow_m3_per_min_t",
                "underaerated_fraction", "system_curve", "law", "geometry", "mesh", "converged"):
        assert key in r
    assert r["mesh"]["axisymmetric"] is False and r["mesh"]["elements"] > 8000
    assert r["mass_balance"]["relative_difference"] < 1e-8
    assert r["static_pressure_pa"] == 100.0
    assert r["geometry"]["ducts"][0]["shape"] == shape


@pytest.mark.slow
def test_the_fan_operating_point_is_on_the_fan_curve_and_the_bins(tmp_path):
    """--fan: the solved operating point's (Q, P) lies on the fan curve (linear between its
    rows) and is the bin's own solve (P is the pressure solved at, Q its plenum inflow)."""
    fan = tmp_path / "fan.csv"
    fan.write_text("airflow_m3_s,static_pressure_pa\n0,400\n0.5,300\n1.0,150\n1.3,0\n")
    out = tmp_path / "f.json"
    code = main(["--diameter", "8", "--depth", "5", "--fan", str(fan), "--json", str(out),
                 "--no-figure", "--elements", "2000", "--no-refinement-check", "-q"])
    assert code == 0
    r = json.loads(out.read_text())
    q, p = r["airflow_m3_s"], r["static_pressure_pa"]
    assert p == pytest.approx(np.interp(q, [0, 0.5, 1.0, 1.3], [400, 300, 150, 0]), rel=1e-8)
    ps = np.array([s["static_pressure_pa"] for s in r["system_curve"]])
    qs = np.array([s["airflow_m3_s"] for s in r["system_curve"]])
    i = np.searchsorted(ps, p)
    assert qs[i - 1] < q < qs[i]


@pytest.mark.parametrize("text, words", [
    ("depth_m,porosity\n0,0.41\n1,1.2\n", "row 3: porosity must be in (0, 1)"),
    ("depth_m,porosity\n0,0.41\n0,0.40\n", "row 3: depth_m 0 does not increase"),
    ("depth,porosity\n0,0.41\n", "header must be depth_m,porosity"),
])
def test_a_bad_porosity_profile_names_its_row(text, words, tmp_path, capsys):
    f = tmp_path / "p.csv"
    f.write_text(text)
    code = main(["--diameter", "8", "--depth", "5", "--pressure", "100", "--porosity-profile",
                 str(f), "--no-figure", "-q"])
    err = capsys.readouterr().err
    assert code == 2 and words in err and err.count("\n") == 1


def test_janssen_makes_the_deep_grain_denser(wheat):
    """--compaction: Janssen's stress grows with depth toward rho_b g R_h/(mu_w K), so the
    porosity of a falling porosity-stress curve falls with depth."""
    from network.bin._material import _profile, janssen_stress

    s = janssen_stress(np.array([0.0, 1.0, 5.0, 200.0]), bulk_density_kg_m3=750.0,
                       diameter_m=8.0, wall_friction=0.5, lateral_ratio=0.5)
    assert s[0] == 0 and np.all(np.diff(s) > 0)
    assert s[-1] == pytest.approx(750.0 * 9.80665 * 2.0 / 0.25, rel=1e-9)
    prof = _profile("wheat", None, None, (np.array([0.0, 3e4]), np.array([0.415, 0.385])),
                    (750.0, 8.0, 0.5, 0.5))
    e = prof(np.array([0.0, 1.0, 5.0]))
    assert e[0] == pytest.approx(0.415) and np.all(np.diff(e) < 0)


def test_the_law_from_a_report_json_is_the_bundled_construction(wheat, tmp_path):
    """--report: a network.report JSON built from the same curves and band gives the same law
    as the bundled files (the horizontal gradients divided by the shift factor the report
    applied), and a report of another grain is refused."""
    from network.bin._material import DATA

    an = json.loads((DATA / "anisotropy_wheat.json").read_text())
    band = json.loads((DATA / "band_wheat.json").read_text())
    f = 0.97
    rep = {"grain": "wheat", "packing": "bed.csv", "porosity_packing": an["porosity"],
           "viscosity_pa_s": an["viscosity_pa_s"], "air_density_kg_m3": an["density_kg_m3"],
           "points": [{"velocity_m_s": u, "converged": True, "porosity_shift_factor": f,
                       "pressure_gradient_packing_pa_per_m": gz,
                       "pressure_gradient_horizontal_pa_per_m": f * gx}
                      for u, gz, gx in zip(an["velocities_m_s"], an["vertical_pa_per_m"],
                                           an["horizontal_pa_per_m"])],
           "band": {"velocities_m_s": band["velocities_m_s"], "beds": band["beds"]}}
    path = tmp_path / "r.json"
    path.write_text(json.dumps(rep))
    mat = network_material("wheat", viscosity_pa_s=MU, density_kg_m3=RHO, report=str(path))
    assert mat.k_coef == pytest.approx(wheat.k_coef, rel=1e-12)
    assert mat.beta_coef == pytest.approx(wheat.beta_coef, rel=1e-12)
    assert mat.anisotropy == pytest.approx(wheat.anisotropy, rel=1e-12)
    with pytest.raises(ValueError, match="a report of wheat, not of --grain soybean"):
        network_material("soybean", viscosity_pa_s=MU, density_kg_m3=RHO, report=str(path))


def test_a_newton_failure_is_exit_1_naming_the_pressure(monkeypatch, capsys):
    """Newton's method stopped before it converges (no iterations allowed): one error line
    naming the static pressure, exit 1."""
    import functools

    monkeypatch.setattr(BinProblem, "solve", functools.partialmethod(BinProblem.solve,
                                                                     maxiter=0))
    code = main(["--diameter", "8", "--depth", "5", "--top", "peaked", "--pressure", "250",
                 "--elements", "1500", "--no-figure", "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert len(err) == 1 and "did not converge at a static pressure of 250 Pa" in err[0]


def test_the_grain_library_copies_agree_with_dem_grains():
    """network may not import dem: the angle of repose (EN 1991-4 phi_r, in dem.grains' notes)
    and Janssen's K and wall friction copied into network.bin are dem.grains' values."""
    from dem.grains import grain
    from network.bin._material import ANGLE_OF_REPOSE, JANSSEN

    for name, (k_lat, mu_w) in JANSSEN.items():
        g = grain(name)
        assert k_lat == pytest.approx(g.lateral_pressure_ratio.value, rel=1e-12)
        assert mu_w == g.wall_friction_steel.value
    for name, (angle, _) in ANGLE_OF_REPOSE.items():
        assert re.search(rf"phi_r {angle:g}\b", grain(name).internal_friction_deg.note)


def test_the_vtk_file_holds_the_mesh_and_its_fields(tmp_path):
    """--vtk: a legacy unstructured grid whose counts match the JSON's mesh, with the nodal
    pressure (the plenum's value at its nodes) and the four cell fields."""
    vtk, js = tmp_path / "b.vtk", tmp_path / "b.json"
    code = main(["--diameter", "6", "--depth", "3", "--pressure", "100", "--elements", "400",
                 "--no-figure", "--no-refinement-check", "-q", "--vtk", str(vtk),
                 "--json", str(js)])
    assert code == 0
    lines = vtk.read_text().splitlines()
    mesh = json.loads(js.read_text())["mesh"]
    head = {ln.split()[0]: ln.split() for ln in lines if ln[:1].isalpha()}
    assert head["POINTS"][1] == str(mesh["nodes"]) and head["CELLS"][1] == str(mesh["elements"])
    assert head["CELL_DATA"][1] == str(mesh["elements"])
    names = [ln.split()[1] for ln in lines if ln.startswith(("SCALARS", "VECTORS"))]
    assert names == ["pressure_pa", "velocity_m_s", "porosity", "airflow_m3_per_min_t",
                     "underaerated"]
    i = lines.index("SCALARS pressure_pa double 1") + 2
    p = np.array(lines[i:i + mesh["nodes"]], dtype=float)
    assert p.max() == 100.0 and p.min() == 0.0
