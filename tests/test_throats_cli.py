"""python -m throats.solve: single-throat JSON and CSV mode (tests call main directly)."""

import csv
import json

import numpy as np
import pytest

from throats.solve import main


def test_readme_command_prints_json(capsys):
    # README's first command: three equal grains 0.2 rbar apart (type a)
    assert main(["--radii", "1", "1", "1", "--sides", "2.2", "2.2", "2.2"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"qstar", "open_area", "contact_type", "error_estimate", "seconds"} <= set(out)
    assert out["contact_type"] == "a"
    assert out["open_area"] == pytest.approx(np.sqrt(3) / 4 * 2.2**2 - np.pi / 2, rel=1e-12)
    assert 0 < out["error_estimate"] < 1e-3
    assert out["qstar"] == pytest.approx(0.0057568, rel=1e-3)   # rtol 1e-5 solve, v1.0


def test_shape_factor_method_and_scale(capsys):
    assert main(["--radii", "3", "3", "3", "--sides", "6.6", "6.6", "6.6",
                 "--method", "shape-factor"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert main(["--radii", "1", "1", "1", "--sides", "2.2", "2.2", "2.2",
                 "--method", "shape-factor"]) == 0
    out1 = json.loads(capsys.readouterr().out)
    assert out["qstar"] == pytest.approx(out1["qstar"], rel=1e-12)   # Q* in rbar units
    assert out["open_area"] == pytest.approx(9 * out1["open_area"], rel=1e-12)


def test_bad_single_throat_returns_1(capsys):
    assert main(["--radii", "1", "1", "1", "--sides", "1", "1", "5"]) == 1
    cap = capsys.readouterr()
    assert json.loads(cap.out)["status"] == "invalid"
    assert "triangle" in cap.err


def test_csv_mode_writes_valid_rows_and_names_bad_ones(tmp_path, capsys):
    src = tmp_path / "in.csv"
    src.write_text("id,r1,r2,r3,l12,l13,l23\n"
                   "a,1,1,1,2.2,2.2,2.2\n"
                   "b,1,1,1,x,2,2\n"
                   "c,3e-3,3e-3,3e-3,6e-3,6e-3,6e-3\n"
                   "d,1,1,1,1.6,1.6,1.6\n"
                   "e,1,0,1,2,2,2\n")
    dst = tmp_path / "out.csv"
    rc = main(["--csv", str(src), "--out", str(dst), "--no-progress"])
    assert rc == 1
    err = capsys.readouterr().err
    assert "row 3:" in err and "cannot parse l12" in err
    assert "row 6:" in err and "radius <= 0" in err
    rows = list(csv.DictReader(dst.open()))
    assert [r["id"] for r in rows] == ["a", "b", "c", "d", "e"]
    assert [r["status"] for r in rows] == ["ok", "invalid", "ok", "closed", "invalid"]
    assert float(rows[2]["qstar"]) == pytest.approx(5.2262e-4, rel=1e-3)  # type d, v1.0
    assert rows[2]["contact_type"] == "d"
    assert float(rows[3]["qstar"]) == 0.0
    assert rows[1]["qstar"] == ""


def test_usage_errors_exit_2():
    with pytest.raises(SystemExit) as exc:
        main(["--radii", "1", "1", "1"])
    assert exc.value.code == 2
    with pytest.raises(SystemExit):
        main(["--csv", "x.csv"])


def test_bench_runs_small(tmp_path, capsys):
    from throats.bench import main as bench_main
    out = tmp_path / "b.json"
    assert bench_main(["--n", "4", "--rtols", "1e-3", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert {"loadavg_start", "platform", "cpu_count", "timestamp"} <= set(data)
    res = data["results"]["fem rtol=0.001"]["packing"]
    assert res["error"]["max"] < 1e-3
    assert "shape-factor" in data["results"]
    assert "fem rtol=0.001" in capsys.readouterr().out
