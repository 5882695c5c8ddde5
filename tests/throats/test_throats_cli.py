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


@pytest.mark.parametrize("radii, sides, words", [
    (["1", "1", "1"], ["1", "1", "5"], "sides [1.0, 1.0, 5.0] do not form a triangle"),
    (["-1", "1", "1"], ["2.2", "2.2", "2.2"], "radius <= 0 in radii [-1.0, 1.0, 1.0]"),
    (["0", "1", "1"], ["2.2", "2.2", "2.2"], "radius <= 0 in radii [0.0, 1.0, 1.0]"),
    (["nan", "1", "1"], ["2.2", "2.2", "2.2"], "non-finite value in radii [nan, 1.0, 1.0]"),
    (["1", "1", "1"], ["2.2", "-2.2", "2.2"], "side length <= 0"),
])
def test_bad_single_throat_is_bad_input_exit_2(capsys, radii, sides, words):
    """A bad throat given as options is bad input: exit 2, one ``error:`` line naming the
    options and what is wrong, nothing on stdout (it was exit 1 after the work, like a bad
    CSV row)."""
    with pytest.raises(SystemExit) as exc:
        main(["--radii", *radii, "--sides", *sides])
    cap = capsys.readouterr()
    err = cap.err.strip().splitlines()
    assert exc.value.code == 2 and cap.out == ""
    assert len(err) == 1 and err[0].startswith(f"error: --radii {' '.join(radii)} --sides ")
    assert words in err[0], err


@pytest.mark.parametrize("scale", [1e-300, 1e-100, 1e80, 1e200, 1e300])
@pytest.mark.parametrize("method", ["shape-factor", "fem"])
def test_any_finite_positive_unit_gives_the_same_qstar(capsys, scale, method):
    """Q* is scale-free: three equal disks 0.2 r apart give the Q* of unit radii at any
    length unit (1e200 overflowed the triangle test, 1e-300 underflowed the area to 'closed');
    the open area scales by scale^2, empty (null) beyond the float range."""
    ref_args = ["--radii", "1", "1", "1", "--sides", "2.2", "2.2", "2.2", "--method", method]
    assert main(ref_args) == 0
    ref = json.loads(capsys.readouterr().out)
    with np.errstate(all="raise"):
        rc = main(["--radii", *[repr(scale)] * 3, "--sides", *[repr(2.2 * scale)] * 3,
                   "--method", method])
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert rc == 0 and out["status"] == "ok" and cap.err == ""
    assert out["qstar"] == pytest.approx(ref["qstar"], rel=1e-9)
    if scale > 1e150:                    # beyond the float range: written empty
        assert out["open_area"] is None
    elif scale < 1e-150:                 # below it: underflows to 0, the status stays 'ok'
        assert out["open_area"] == 0.0
    else:
        assert out["open_area"] == pytest.approx(ref["open_area"] * scale**2, rel=1e-9)


def test_bad_rows_and_short_rows_are_error_lines(tmp_path, capsys):
    """Bad CSV rows keep exit 1 and are each an ``error:`` line; a short row says how many
    values it has (it said ``cannot parse l23=None``)."""
    src = tmp_path / "in.csv"
    src.write_text("r1,r2,r3,l12,l13,l23\n1,1,1,2.2,2.2,2.2\n1,1,1,2.2,2.2\n1,-1,1,2.2,2.2,2.2\n")
    assert main(["--csv", str(src), "--out", str(tmp_path / "o.csv"), "--method",
                 "shape-factor"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err[0] == f"error: {src} row 3: invalid: the row has 5 of 6 values"
    assert err[1].startswith(f"error: {src} row 4: invalid: radius <= 0")


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


@pytest.mark.slow
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
