"""The grain of a bed comes from the bed: its companion JSON's template, or ``--grain``.

A report or solve for one grain on another grain's bed is refused (exit 2, one ``error:`` line
naming both, nothing written, no input touched); a bed without a template record is taken to be
the ``--grain`` given with one ``warning:`` line; ``network.solve`` compares a bed with its own
grain's D272 line, and with none where the grain is unknown.
"""

from __future__ import annotations

import json
import shutil

import pytest

from network._grains import packing_grain, template_grain
from network.curve import main as curve_main
from network.packing import default_packing_path
from network.report import main as report_main
from network.solve import main as solve_main

DATA = default_packing_path().parent
WHEAT = DATA / "wheat_grains.csv"


def _snapshot(*paths):
    return {p: p.read_bytes() for p in paths}


def test_template_grain_reads_the_companion_json_and_the_bundled_names(tmp_path):
    assert template_grain(WHEAT) == ("wheat", "wheat")
    assert template_grain(DATA / "soybean_grains.csv") == ("soybean", "soybean")
    assert template_grain(default_packing_path()) == ("soybean", None)
    bed = tmp_path / "bed.csv"
    shutil.copy(default_packing_path(), bed)
    assert template_grain(bed) == (None, None)
    (tmp_path / "bed.json").write_text(json.dumps({"template": "my_bean"}))
    assert template_grain(bed) == (None, "my_bean")
    (tmp_path / "bed.json").write_text(json.dumps({"template": "Shelled corn"}))
    assert template_grain(bed) == ("shelled_corn", "Shelled corn")


def test_packing_grain_warns_once_for_a_bed_without_a_record(tmp_path, caplog):
    bed = tmp_path / "bed.csv"
    shutil.copy(default_packing_path(), bed)
    with caplog.at_level("WARNING"):
        assert packing_grain(bed, "wheat") == "wheat"
    assert len(caplog.records) == 1 and "no grain template record" in caplog.text \
        and "taken to be wheat (as --grain says)" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        assert packing_grain(bed) is None
        assert packing_grain(WHEAT) == "wheat" and packing_grain(WHEAT, "WHEAT") == "wheat"
    assert caplog.records == []


def test_the_report_says_so_in_one_warning_line(tmp_path, monkeypatch, capsys):
    """The report on a bed without a template record, --grain given: one 'warning:' line
    (the run then stops at an impossible --porosity here, before any solve)."""
    monkeypatch.chdir(tmp_path)
    bed = tmp_path / "bed.csv"
    shutil.copy(default_packing_path(), bed)
    assert report_main(["--packing", str(bed), "--grain", "wheat", "--porosity", "1.5",
                        "-q"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert [e for e in err if e.startswith("warning:")] == [
        f"warning: {bed} has no grain template record: taken to be wheat (as --grain says); "
        "its D272 line and grain data are wheat's"]


@pytest.mark.parametrize("command, argv", [
    (report_main, ["--grain", "soybean", "--packing", str(WHEAT)]),
    (solve_main, [str(WHEAT), "--grain", "soybean"]),
    (curve_main, [str(WHEAT), "--grain", "soybeans", "--velocities", "0.01,0.1"]),
])
def test_one_grain_on_another_grains_bed_is_refused(command, argv, tmp_path, monkeypatch,
                                                    capsys):
    monkeypatch.chdir(tmp_path)
    before = _snapshot(WHEAT, WHEAT.with_suffix(".json"))
    out = tmp_path / "out.json"
    assert command([*argv, "--json", str(out), "-q"]) == 2
    cap = capsys.readouterr()
    err = cap.err.strip().splitlines()
    assert cap.out == "" and len(err) == 1, cap
    assert err[0].startswith("error: --grain soy") and "is a bed of wheat" in err[0] \
        and "give --grain wheat" in err[0]
    assert _snapshot(WHEAT, WHEAT.with_suffix(".json")) == before
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_solve_compares_a_bed_with_its_own_grain(tmp_path, capsys):
    """The wheat bed: wheat's D272 (27000 Pa s^2/m^3, 8.77 s/m), no soybean or thesis line; a
    bed of unknown grain: no D272 line and ``asabe_d272`` null in the JSON."""
    out = tmp_path / "w.json"
    assert solve_main([str(WHEAT), "--json", str(out), "-q"]) == 0
    text = capsys.readouterr().out
    r = json.loads(out.read_text())
    assert r["grain"] == "wheat" and "thesis_lsv_reference_pa" not in r
    d = r["comparisons"]["asabe_d272"]
    g = 27000.0 * 0.013**2 / __import__("math").log1p(8.77 * 0.013)
    assert d["grain"] == "wheat" and d["pressure_gradient_pa_per_m"] == pytest.approx(g, rel=1e-12)
    assert f"ASABE D272 (wheat) {0.25 * g:.4g} Pa" in text
    assert "soybean" not in text and "thesis" not in text
    bed = tmp_path / "bed.csv"
    shutil.copy(default_packing_path(), bed)
    before = bed.read_bytes()
    assert solve_main([str(bed), "--json", str(out), "-q"]) == 0
    cap = capsys.readouterr()
    r = json.loads(out.read_text())
    assert r["grain"] is None and r["comparisons"]["asabe_d272"] is None
    assert "no ASABE D272 line: the bed's grain is unknown (give --grain)" in cap.out
    assert "soybean" not in cap.out and "thesis" not in cap.out and cap.err == ""
    assert bed.read_bytes() == before


def test_grain_names_take_spaces_and_any_case(tmp_path, monkeypatch, capsys):
    """'Rough Rice' is rough_rice: the report gets past the name (and stops at the missing
    bundled bed of that grain, exit 2, nothing written)."""
    from network._grains import grain_key
    assert grain_key("shelled corn") == grain_key("Shelled_Corn") == "shelled_corn"
    assert grain_key("rough rice") == grain_key("Rough_Rice") == "rough_rice"
    monkeypatch.chdir(tmp_path)
    assert report_main(["--grain", "Rough Rice", "--particle-density", "1300", "-q"]) == 2
    err = capsys.readouterr().err
    assert "unknown grain" not in err and "no bundled packing for rough_rice" in err
    assert list(tmp_path.iterdir()) == []


def test_a_depth_thinner_than_a_grain_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    for command, argv in ((report_main, ["--no-band", "--no-figures"]), (solve_main, []),
                          (curve_main, ["--velocities", "0.01,0.1"])):
        assert command([*argv, "--depth", "1e-6", "-q"]) == 2
        cap = capsys.readouterr()
        err = cap.err.strip().splitlines()
        assert err[-1].startswith("error: --depth 1e-06 m is thinner than one grain") \
            and "mm across" in err[-1] and cap.out == ""
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_solve_marks_an_unconverged_inertial_answer(tmp_path, capsys, monkeypatch):
    """network.solve whose nonlinear solve stops short (forced): the line says so, the JSON
    says converged: false, exit 1 after the JSON is written."""
    import dataclasses

    import network.solve as solve_module
    real = solve_module.solve_axes

    def stops_short(*args, **kwargs):
        out = []
        for res in real(*args, **kwargs):
            pts = [dataclasses.replace(pt, converged=False) for pt in res.inertial["points"]]
            out.append(dataclasses.replace(res, inertial=dict(res.inertial, points=pts)))
        return out

    monkeypatch.setattr(solve_module, "solve_axes", stops_short)
    out = tmp_path / "s.json"
    assert solve_main(["--json", str(out), "-q"]) == 1
    cap = capsys.readouterr()
    r = json.loads(out.read_text())
    assert r["converged"] is False and r["inertial_solver"]["converged"] is False
    assert "NOT CONVERGED: the nonlinear solve stopped short" in cap.out
    assert "error: the nonlinear solve did not converge along z at 0.013 m/s" in cap.err


@pytest.mark.slow
def test_impossible_and_unreachable_porosities_are_refused_at_once(tmp_path, monkeypatch,
                                                                   capsys):
    """--porosity 0.9 (no bed of grains is that loose) and 0.2 (denser than any packing of
    equal spheres) are refused before any packing by network.report and dem.pack; 0.45 for
    soybean in the bundled bed's box is refused at once with the one recorded range, quoted the
    same by the report (packing anew or moving along the band) and by dem.pack."""
    import time

    from dem.pack import main as pack_main
    from network.core import reach_text, recorded_reach
    monkeypatch.chdir(tmp_path)
    box = ["--scene", "box", "--size", "0.05", "0.05", "--height", "0.05", "--grain", "soybean"]
    t0 = time.perf_counter()
    for p, words in (("0.9", "no static bed of grains is that loose"),
                     ("0.2", "no packing of grains is that dense")):
        assert report_main(["--porosity", p, "-q"]) == 2
        assert f"error: --porosity {p}: {words}" in capsys.readouterr().err
        assert pack_main([*box, "--fill", "grow", "--porosity", p, "--out", "b.csv",
                          "--quiet"]) == 2
        assert f"error: --porosity {p}: {words}" in capsys.readouterr().err
        assert pack_main(["--scene", "box", "--porosity", p, "--out", "s.csv", "--quiet"]) == 2
        assert f"error: --porosity {p}: {words}" in capsys.readouterr().err      # spheres too
    quoted = reach_text(recorded_reach("soybean"))
    assert quoted.startswith("0.3490-0.4114 ")
    for argv in (["--porosity", "0.45"], ["--porosity", "0.45", "--move-along-band"]):
        assert report_main([*argv, "-q"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and quoted in err[0], err
    assert pack_main([*box, "--fill", "grow", "--porosity", "0.45", "--out", "b.csv",
                      "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and quoted in err[0], err
    assert time.perf_counter() - t0 < 30          # refusals, not packings (a packing: minutes)
    assert list(tmp_path.iterdir()) == []
