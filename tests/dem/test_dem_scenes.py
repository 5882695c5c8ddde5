"""Scenes, packing procedure, measurements and file I/O of dem."""

import numpy as np
import pytest

from dem import (SCENES, Container, Material, Region, coordination_numbers, generate_spheres, intensity_g,
                 lens_volume, pack_bed, PackOptions, RunOptions, porosity_in_region, porosity_in_spheres, read_packing, sphere_volume,
                 thesis_particle_count, vibrate_bed, VibrationOptions, write_packing)

TINY = Container("box", (0.03, 0.02), 0.03)


@pytest.mark.slow
def test_thesis_particle_counts():
    # Appendix A/B: num = int((1 - 0.408) V / (4/3 pi rbar^3)), rbar = 3.25 mm; thesis 4.1.1
    # reports 5 146 (rect bin) and 18 188 (cylinder) spheres.
    assert thesis_particle_count(SCENES["rect-bin"], 0.408) == 5146
    assert thesis_particle_count(SCENES["cyl-bin"], 0.408) == 18188


@pytest.mark.slow
def test_intensity_matches_thesis_list():
    # thesis 3.2: 0.45, 0.91, 1.81, 2.72, 3.62 g for 0.5-4 mm at 15 Hz
    got = [intensity_g(15, a) for a in (0.0005, 0.001, 0.002, 0.003, 0.004)]
    np.testing.assert_allclose(got, [0.45, 0.91, 1.81, 2.72, 3.62], atol=0.006)


@pytest.mark.slow
def test_lens_volume_limits_and_hemisphere():
    R = 1.0
    assert lens_volume(R, 0.5, 0.2) == pytest.approx(sphere_volume(0.5))  # inside
    assert lens_volume(R, 0.5, 1.6) == 0.0  # apart
    # two unit spheres one radius apart: 5 pi / 12 (classical lens)
    assert lens_volume(1.0, 1.0, 1.0) == pytest.approx(5 * np.pi / 12, rel=1e-12)


@pytest.mark.slow
def test_porosity_in_sphere_and_region_exact_cases():
    # one sphere r = 1 mm centred in a measurement sphere of 2 mm: porosity 1 - 1/8
    c = np.array([[0.0, 0.0, 0.0]])
    r = np.array([0.001])
    assert porosity_in_spheres(c, r, c, 0.002)[0] == pytest.approx(1 - 1 / 8, rel=1e-12)
    # a sphere cut in half by the region's floor: solid = half a sphere (quadrature ~1e-3)
    box = Region("box", (-0.002, -0.002, 0.0), (0.002, 0.002, 0.004))
    expected = 1 - 0.5 * sphere_volume(0.001) / box.volume
    assert porosity_in_region(c, r, box) == pytest.approx(expected, abs=2e-3)
    cyl = Region("cylinder", (0, 0, -0.01), (0, 0, 0.01), radius=0.01)
    assert porosity_in_region(c, r, cyl) == pytest.approx(1 - sphere_volume(0.001) / cyl.volume, rel=1e-12)


@pytest.mark.slow
def test_coordination_counts_on_a_square():
    # four touching spheres on a square of side 2r: 2 contacts each, 3 neighbours within 1.5*2r*sqrt2
    x = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [2, 2, 0]], float)
    r = np.ones(4)
    np.testing.assert_array_equal(coordination_numbers(x, r, contact_tol_m=1e-9), [2, 2, 2, 2])
    np.testing.assert_array_equal(coordination_numbers(x, r, cutoff_m=2.9), [3, 3, 3, 3])


@pytest.mark.slow
def test_generated_spheres_do_not_overlap_and_stay_inside():
    rng = np.random.default_rng(5)
    cyl = Container("cylinder", (0.05,), 0.04)
    x, r = generate_spheres(cyl, 300, 0.002, 0.0027, rng)
    assert len(r) == 300
    d = np.linalg.norm(x[:, None] - x[None], axis=2) + np.eye(300)
    assert np.all(d >= r[:, None] + r[None] - 1e-15)
    assert np.all(np.hypot(x[:, 0], x[:, 1]) + r <= 0.025 + 1e-12)
    assert np.all((x[:, 2] - r >= 0) & (x[:, 2] + r <= 0.04))


@pytest.mark.slow
@pytest.mark.parametrize("kwargs,match", [
    (dict(porosity=0.2), "unreachable"),
    (dict(porosity=0.30), "unreachable"),
    (dict(porosity=1.2), r"porosity must be in \(0, 1\)"),
])
def test_impossible_porosity_is_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        pack_bed(TINY, **kwargs)


@pytest.mark.slow
def test_container_smaller_than_grain_is_refused():
    with pytest.raises(ValueError, match="smaller than a grain"):
        pack_bed(Container("box", (0.005, 0.02), 0.05))


@pytest.mark.slow
@pytest.mark.parametrize("field", ["kn_n_m", "ks_n_m", "wall_kn_n_m", "density_kg_m3"])
def test_non_positive_stiffness_is_refused(field):
    with pytest.raises(ValueError, match=field):
        Material(**{field: 0.0})
    with pytest.raises(ValueError, match=field):
        Material(**{field: -1.0})


KW = dict(rng=7, options=PackOptions(grow_steps=500, lid_headroom=1.0), run=RunOptions(tol=5e-3, max_steps=20000))


@pytest.fixture(scope="module")
def tiny_bed():
    # settled to a force ratio 5e-3 (about 20 000 steps, 2 s): at rest for dem.vibrate's check
    return pack_bed(TINY, **KW)


@pytest.mark.slow
def test_same_seed_same_packing_and_io_roundtrip(tmp_path, tiny_bed):
    a = tiny_bed
    b = pack_bed(TINY, **KW)
    np.testing.assert_array_equal(a.centers, b.centers)
    np.testing.assert_array_equal(a.radii, b.radii)
    x7, _ = generate_spheres(TINY, 50, 0.002, 0.0027, np.random.default_rng(7))
    x8, _ = generate_spheres(TINY, 50, 0.002, 0.0027, np.random.default_rng(8))
    assert not np.array_equal(x7, x8)
    # the packing is physical: every sphere inside the bin, overlaps below 1 % of a radius
    s = a.summary
    assert s["n_spheres"] == thesis_particle_count(TINY, 0.408)
    assert s["max_overlap_fraction"] < 0.01
    assert np.all(np.abs(a.centers[:, 0]) + a.radii <= 0.015 + 1e-5)
    assert np.all(a.centers[:, 2] - a.radii >= -1e-5)
    # closed-volume porosity is the target by construction (Eq. 3.7)
    assert s["porosity_closed_volume"] == pytest.approx(0.408, abs=1e-12)
    p = tmp_path / "p.csv"
    write_packing(p, a.centers, a.radii, s)
    x, r, js = read_packing(p)
    np.testing.assert_allclose(x, a.centers, rtol=1e-8, atol=1e-12)
    assert js["n_spheres"] == s["n_spheres"]


@pytest.mark.slow
def test_vibration_records_histories(tiny_bed):
    # amplitude 0: the library allows a control run (the CLI refuses A <= 0)
    res = vibrate_bed(tiny_bed.centers, tiny_bed.radii, TINY,
                      vibration=VibrationOptions(freq_hz=15, amplitude_m=0.0, duration_s=0.02,
                                                 record_every_s=0.005, snapshot_times_s=[0.01]),
                      run=RunOptions(tol=1e-3, max_steps=200))
    # 0.02 s recorded every 0.005 s, plus the initial and the post-settling records
    assert len(res.times_s) == 6 and res.porosity_spheres.shape == (6, 5)
    assert 0.01 in res.snapshots
    for h in (res.porosity_spheres, res.porosity_interior, res.porosity_global):
        assert np.all((h > 0) & (h < 1))
    assert np.all(res.centers[:, 2] - res.radii > -1e-4)  # nobody fell through the floor
    assert res.summary["intensity_g"] == 0.0
    with pytest.raises(ValueError, match="freq_hz must be finite and > 0"):
        VibrationOptions(freq_hz=0.0, amplitude_m=0.001, duration_s=0.1)
    with pytest.raises(ValueError, match="amplitude_m must be finite and >= 0"):
        VibrationOptions(amplitude_m=-1e-3)
    with pytest.raises(ValueError, match="snapshot_times_s must be finite and >= 0"):
        VibrationOptions(snapshot_times_s=[0.01, float("nan")])
    with pytest.raises(ValueError, match="settle_time_s is not taken"):
        vibrate_bed(tiny_bed.centers, tiny_bed.radii, TINY, run=RunOptions(settle_time_s=0.1))
    with pytest.raises(TypeError, match="vibration must be a VibrationOptions"):
        vibrate_bed(tiny_bed.centers, tiny_bed.radii, TINY, vibration={"freq_hz": 15.0})


@pytest.mark.slow
def test_clis_refuse_bad_arguments_and_vibrate_runs(tmp_path, tiny_bed, capsys):
    import importlib  # dem.pack is also the name of the packing function

    pack_main = importlib.import_module("dem.pack").main
    vib_main = importlib.import_module("dem.vibrate").main
    assert pack_main(["--scene", "box", "--out", str(tmp_path / "x.csv")]) == 2
    assert pack_main(["--scene", "rect-bin", "--kn", "0", "--out", str(tmp_path / "x.csv")]) == 2
    assert not (tmp_path / "x.csv").exists()
    p = tmp_path / "bed.csv"
    write_packing(p, tiny_bed.centers, tiny_bed.radii, tiny_bed.summary)
    out = tmp_path / "vib"
    assert vib_main([str(p), "--amplitude", "0.001", "0.002", "--duration", "0.01", "--out", str(out), "--quiet",
                     "--settle-steps", "200"]) == 0
    assert (out / "vib_1mm.csv").exists() and (out / "series.json").exists()
    assert "1.81 g" in capsys.readouterr().out
    # bad input: each a one-line error and exit 2
    for bad, match in [(["--amplitude", "0"], "amplitudes must be > 0"), (["--amplitude", "-0.001"], "> 0"),
                       (["--amplitude", "0.001", "--freq", "0"], "--freq must be > 0"),
                       (["--intensity", "10.5"], "above 10 g")]:
        assert vib_main([str(p), *bad, "--out", str(out), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert match in err and err.count("\n") == 1
    bare = tmp_path / "bare.csv"
    write_packing(bare, tiny_bed.centers, tiny_bed.radii)  # no JSON: no container
    assert vib_main([str(bare), "--amplitude", "0.001", "--out", str(out), "--quiet"]) == 2
    assert "no container" in capsys.readouterr().err
    loose = tmp_path / "loose.csv"  # spheres in the air: not at rest
    x, r = generate_spheres(TINY, 40, 0.0027, 0.0037, np.random.default_rng(1))
    write_packing(loose, x, r, {"container": TINY.to_dict()})
    assert vib_main([str(loose), "--amplitude", "0.001", "--out", str(out), "--quiet"]) == 2
    assert "not at rest" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_modules_do_not_shadow_the_library_functions():
    # `import dem.pack` binds the submodule to the attribute dem.pack: the library functions
    # therefore have other names (pack_bed, vibrate_bed) than the CLI modules
    import importlib

    import dem

    importlib.import_module("dem.pack")
    importlib.import_module("dem.vibrate")
    assert callable(dem.pack_bed) and callable(dem.vibrate_bed)
    assert dem.pack_bed.__module__ == "dem._procedures"
    assert dem.vibrate_bed.__module__ == "dem._vibrate"
