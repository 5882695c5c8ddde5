"""``python -m network.paths``: tortuosity >= 1 for paths on the tessellation,
entries checked, a path traced twice counted once, one stated depth for the comparisons; bad
input exits 2 with one line."""

import json
import sys

import numpy as np
import pytest

from network import random_packing
from network._grains import d272_constants
from network.flow import asabe_d272_gradient
from network.paths.__main__ import main
from network.solve import main as solve_main

SCENE = "network/data/soybean_default.csv"


@pytest.fixture(scope="module")
def bed(tmp_path_factory):
    d = tmp_path_factory.mktemp("paths")
    pk = random_packing(386, solid_fraction=0.592, aspect=(0.04, 0.04, 0.06), rng=5,
                        max_sweeps=300)
    p = d / "bed.csv"
    np.savetxt(p, np.column_stack([pk.centers, pk.radii]), delimiter=",", header="x,y,z,r",
               comments="")
    np.savetxt(d / "bed_mm.csv", np.column_stack([pk.centers * 1e3, pk.radii * 1e3]),
               delimiter=",", header="x,y,z,r", comments="")
    return p


def _run(argv, tmp_path):
    js = tmp_path / "o.json"
    assert main(argv + ["--json", str(js)]) == 0
    return json.loads(js.read_text())


def test_paths_on_the_tessellation_have_tortuosity_at_least_one(tmp_path, capsys):
    out = _run([SCENE, "--entries", "8", "--kind", "shortest", "--no-branched"], tmp_path)
    paths = out["paths"]
    assert len(paths) == 8 and all(p["status"] == "ok" for p in paths)
    # L0 is the path's own axial span, shorter than the bed: T (smoothed) and T raw >= 1
    assert all(p["depth_m"] < out["depth_m"] for p in paths)
    assert min(p["tortuosity"] for p in paths) >= 1.0
    assert all(p["tortuosity_raw"] == pytest.approx(p["tortuosity_span"]) for p in paths)
    assert "own axial span" in out["conventions"]["tortuosity"]


def test_duplicate_paths_are_listed_but_counted_once(bed, tmp_path, capsys):
    out = _run([str(bed), "--entry", "0.02", "0.02", "--entry", "0.02", "0.02",
                "--kind", "widest"], tmp_path)
    assert [p["duplicate_of"] for p in out["paths"]] == [None, 0]
    assert len(out["branched"]) == 1
    assert "same as path 0" in capsys.readouterr().out
    # built paths keep the thesis's L0: the bed depth
    assert out["paths"][0]["depth_m"] == out["depth_m"]


def test_comparison_depth_is_stated_and_the_thesis_only_at_its_depth(bed, tmp_path, capsys):
    out = _run([str(bed), "--entries", "2", "--kind", "narrowest", "--grain", "soybean"],
               tmp_path)
    t45 = out["table_4_5_pa"]
    assert out["comparison_depth_m"] == 0.25
    assert t45["ASABE D272"]["0.013"] == pytest.approx(asabe_d272_gradient(0.013) * 0.25)
    assert round(t45["ASABE D272"]["0.013"], 2) == 2.28          # the thesis's Table 4.5
    b = out["branched"]
    assert t45["branched model"]["0.013"] == pytest.approx(
        np.mean([x["average"]["MFx3"]["0.013"] / x["path_depth_m"] for x in b]) * 0.25)
    assert "measured (thesis)" in t45 and "measured 2.44 Pa" in capsys.readouterr().out
    # Ergun as network.solve computes it: the interior sample's exact porosity, Sauter diameter
    # (before: sphere volume over the bounding box and the mean diameter, 0.430 and 1.00 Pa
    # on the bundled scene where network.solve said 0.399 and 1.35 Pa)
    assert solve_main([str(bed), "--stokes", "--json", str(tmp_path / "s.json")]) == 0
    solved = json.loads((tmp_path / "s.json").read_text())
    capsys.readouterr()
    ergun = [k for k in t45 if k.startswith("Ergun")]
    assert ergun == [f"Ergun (porosity {solved['porosity']:.3f})"]
    assert t45[ergun[0]]["0.013"] == pytest.approx(
        solved["comparisons"]["ergun"]["pressure_drop_pa"], rel=1e-9)
    out = _run([str(bed), "--entries", "2", "--kind", "narrowest", "--depth", "0.5",
                "--grain", "soybean"], tmp_path)
    assert "measured (thesis)" not in out["table_4_5_pa"]
    text = capsys.readouterr().out
    assert "2.44" not in text and "Pa over 0.5 m" in text


def test_the_comparisons_are_of_the_beds_own_grain(bed, tmp_path, capsys):
    """A wheat bed (its companion JSON's template) is set beside wheat's D272 line, with none of
    the thesis's soybean values; a bed of unknown grain gets no D272 row; a --grain that
    contradicts the JSON exits 2."""
    wheat = tmp_path / "wheat_bed.csv"
    wheat.write_text(bed.read_text())
    wheat.with_suffix(".json").write_text(json.dumps({"template": "wheat"}))
    argv = ["--entries", "2", "--kind", "narrowest"]
    out = _run([str(wheat), *argv], tmp_path)
    a, b = d272_constants("wheat")
    assert out["grain"] == "wheat" and out["thesis"] is None
    t45 = out["table_4_5_pa"]
    for u in (0.013, 0.027):
        assert t45["ASABE D272"][f"{u:g}"] == pytest.approx(
            a * u**2 / np.log1p(b * u) * 0.25, rel=1e-12)
    assert t45["ASABE D272"]["0.013"] != pytest.approx(asabe_d272_gradient(0.013) * 0.25)
    assert "measured (thesis)" not in t45
    text = capsys.readouterr().out
    assert "ASABE D272 (wheat)" in text and "soybean" not in text
    assert "(thesis 1.40)" not in text and "measured 2.44" not in text

    out = _run([str(bed), *argv], tmp_path)
    assert out["grain"] is None and "ASABE D272" not in out["table_4_5_pa"]
    assert "no ASABE D272 line: the bed's grain is unknown (give --grain)" in (
        capsys.readouterr().out)

    assert main([str(wheat), *argv, "--grain", "soybean"]) == 2
    assert "is a bed of wheat" in capsys.readouterr().err.strip().splitlines()[-1]


def test_units_mm_gives_the_same_paths(bed, tmp_path, capsys):
    m = _run([str(bed), "--entry", "0.02", "0.02", "--kind", "widest", "--no-branched"],
             tmp_path)
    mm = _run([str(bed.with_name("bed_mm.csv")), "--units", "mm", "--entry", "20", "20",
               "--kind", "widest", "--no-branched"], tmp_path)
    assert mm["paths"][0]["tortuosity"] == pytest.approx(m["paths"][0]["tortuosity"])
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("argv, words", [
    ([SCENE, "--entries", "0"], "--entries n must be 1-10000"),
    ([SCENE, "--entries", "-3"], "--entries n must be 1-10000 (entry points: 1e8 ran out of "
                                 "memory), got -3"),
    ([SCENE, "--entries", "100000000"], "--entries n must be 1-10000"),
    ([SCENE, "--velocity", "inf"], "--velocity must be finite and > 0 m/s, got [inf]"),
    ([SCENE, "--entry", "0.5", "0.02"], "--entry 0.5 0.02 lies outside the bed, which spans x"),
    ([SCENE, "--entry", "0.02", "0.5", "--axis", "X"], "spans y -1.117e-05..0.072987, z"),
    ([SCENE, "--depth", "0"], "--depth must be finite and > 0"),
    ([SCENE, "--viscosity", "-1.8e-5"], "--viscosity must be finite and > 0"),
    ([SCENE, "--plot", "no/dir/p.png"], "--plot no/dir/p.png: folder no/dir does not exist"),
    ([SCENE, "--json", "no/dir/p.json"], "folder no/dir does not exist"),
    ([SCENE, "--axis", "q"], "invalid choice: 'q'"),
    ([SCENE, "--grain", "wheat"], "--grain wheat: network/data/soybean_default.csv is a bed of "
                                  "soybean"),
    (["--standin", "0.05", "0.05", "0.05", "--grain", "wheat"],
     "--grain wheat: the stand-in (--standin) has soybean's diameters"),
])
def test_bad_options_exit_2(argv, words, capsys):
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("error: ") and words in err


@pytest.mark.parametrize("content, words", [
    ("", "bad.csv"),
    ("x,y,z,r\n" + "".join(f"{i},{i},{i % 2},0.003\n" for i in range(6)) + "nan,0,0,0.003\n",
     "row 8"),
    ("x,y,z,r\n0,0,0,1\n1,0,0,1\n0,1,0,1\n", "too few spheres"),
    ("x,y,z,r\n" + "".join(f"{i % 3 * 0.01},{i // 3 * 0.01},0.05,0.003\n" for i in range(9)),
     "coplanar"),
])
def test_bad_packings_exit_2(content, words, tmp_path, capsys):
    p = tmp_path / "bad.csv"
    p.write_text(content)
    assert main([str(p), "--kind", "shortest", "--entries", "1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and words in err


def test_plot_without_matplotlib_names_the_extra(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)     # import matplotlib fails
    assert main([SCENE, "--plot", str(tmp_path / "p.png")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pip install '.[plot]'" in err


def test_pressure_along_the_paths_falls_with_height(tmp_path):
    # --pressure read the solver's pressures by tetrahedron while the solver had merged
    # tetrahedra into pore bodies: scrambled values, 18 of 40 drops negative (the audit)
    out = tmp_path / "p.json"
    assert main([SCENE, "--entries", "6", "--kind", "shortest", "--pressure",
                       "--json", str(out)]) == 0
    along = json.loads(out.read_text())["pressure_along_paths"]
    assert len(along) >= 4
    for a in along:
        pos, pr = np.array(a["position_m"]), np.array(a["pressure_pa"])
        assert a["dp_pa"] > 0 and np.corrcoef(pos, pr)[0, 1] < -0.9
