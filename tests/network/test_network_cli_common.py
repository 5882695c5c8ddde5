"""The shared CLI conventions of network.solve/curve/throatlist/paths: every option has
help with its unit or default, exit codes 0/1/2 with one ``error:`` line, numpy/scipy warnings
captured, output folders and matplotlib checked before any work; curve and throatlist bad input."""

import argparse
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

from network import _cli, curve, default_packing_path, solve, throatlist
from network.paths import __main__ as paths

PARSERS = {"solve": solve.build_parser, "curve": curve.build_parser,
           "throats": throatlist.build_parser, "paths": paths._parser}


@pytest.mark.parametrize("name", sorted(PARSERS))
def test_help_explains_every_option(name, capsys):
    ap = PARSERS[name]()
    for action in ap._actions:
        if action.dest == "help" or action.help == argparse.SUPPRESS:   # removed options
            continue
        assert action.help and len(action.help) > 12, (name, action.dest)
    with pytest.raises(SystemExit) as exc:
        ap.parse_args(["--help"])
    assert exc.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "--units {m,cm,mm}" in text and "length unit of the packing file" in text
    if name != "throats":
        assert "Pa s, > 0" in text and "(default: 1.932e-05)" in text
    if name in ("solve", "paths"):
        assert "(default: 0.25)" in text and "m, > 0" in text


def test_negative_numbers_are_values_and_axis_any_case():
    ap = solve.build_parser()
    args = ap.parse_args(["--viscosity", "-1.8e-5", "--axis", "ALL",
                          "--sample", "-1e-2", "1", "-.5", "1", "0", "2E-1"])
    assert args.viscosity == -1.8e-5 and args.axis == "all"
    assert args.sample == [-1e-2, 1.0, -0.5, 1.0, 0.0, 0.2]


def test_run_captures_warnings_into_one_line(capsys):
    def body(args):
        np.log(np.zeros(3))                                   # RuntimeWarning x1
        warnings.warn("scipy said something", UserWarning)
        print("result")
        return 0

    assert _cli.run(body, _cli.CliParser(prog="t"), []) == 0
    out, err = capsys.readouterr()
    assert out == "result\n" and err.count("\n") == 1
    assert err.startswith("warning: 2 numerical warning(s)") and "divide by zero" in err


@pytest.mark.parametrize("exc, code, words", [
    (_cli.CliError("bad value 3", 2), 2, "error: bad value 3"),
    (_cli.CliError("solver diverged", 1), 1, "error: solver diverged"),
    (KeyError("centers"), 1, "error: KeyError: 'centers' (an internal error"),
    (KeyboardInterrupt(), 1, "error: interrupted"),
])
def test_exit_codes(exc, code, words, capsys):
    def body(args):
        raise exc

    assert _cli.run(body, _cli.CliParser(prog="t"), []) == code
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(words)


def test_computing_and_bad_input_map_exceptions():
    with pytest.raises(_cli.CliError) as e:
        with _cli.bad_input():
            open("/no/such/file.csv")
    assert e.value.code == 2 and str(e.value) == "No such file or directory: /no/such/file.csv"
    with pytest.raises(_cli.CliError) as e:
        with _cli.computing():
            raise RuntimeError("no convergence")
    assert e.value.code == 1


def test_unwritable_folder_is_refused(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        if not os.access(ro, os.W_OK):                          # root can write anyway
            with pytest.raises(ValueError, match="is not writable"):
                _cli.check_outputs(json=ro / "o.json")
    finally:
        ro.chmod(0o700)
    _cli.check_outputs(json=tmp_path / "o.json", plot=None)      # fine
    if os.path.isdir("/proc"):          # os.access says yes to root there; the probe file fails
        with pytest.raises(ValueError, match="--json /proc/o.json: folder /proc is not writable"):
            _cli.check_outputs(json="/proc/o.json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ro"]   # the probe leaves nothing


def test_outputs_may_not_overwrite_the_inputs_or_each_other(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    bed = tmp_path / "bed.csv"
    bed.write_bytes(default_packing_path().read_bytes())
    companion = '{"container": {"kind": "box", "size_m": [1, 1]}}'
    (tmp_path / "bed.json").write_text(companion)
    cases = [
        (solve, ["--json", "bed.csv"], "--json bed.csv: the same file as the packing file"),
        (solve, ["--json", "bed.json"], "--json bed.json: the same file as the packing's "
                                        "companion JSON (its container)"),
        (solve, ["--pores-csv", "p.csv", "--throats-csv", "./p.csv"],
         "--throats-csv p.csv: the same file as --pores-csv p.csv"),
        (solve, ["--axis", "all", "--pores-csv", "p.csv", "--json", "p_x.csv"],
         "--pores-csv p_x.csv: the same file as --json p_x.csv"),
        (curve, ["--csv", "c.csv", "--json", "c.csv"], "--csv c.csv: the same file as --json"),
        (curve, ["--json", "c.json", "--plot", "c.txt"], "--plot c.txt: matplotlib cannot "
                                                        "write .txt; use one of"),
        (throatlist, ["--out", "bed.csv"], "--out bed.csv: the same file as the packing file"),
        (paths, ["--json", "j.json", "--plot", "j.json"], "--plot j.json: the same file as"),
    ]
    for mod, argv, words in cases:
        assert mod.main(["bed.csv"] + argv) == 2, argv
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and words in err, (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bed.csv", "bed.json"]
    assert bed.read_bytes() == default_packing_path().read_bytes()
    assert (tmp_path / "bed.json").read_text() == companion


@pytest.mark.parametrize("argv, words", [
    (["--velocities", "0.01,-0.2"], "--velocities value -0.2 must be finite and > 0"),
    (["--velocities", "0.3:0.01:0"], "--velocities '0.3:0.01:0': n must be 1 to 200 points, got 0"),
    (["--grain", "oats"], "unknown grain 'oats'; known grains: soybean, wheat"),
    (["--grain", "rapeseed"], "no sourced ASABE D272 constants for canola"),
    (["--density", "-1.2"], "--density must be finite and > 0, got -1.2"),
    (["--viscosity", "-1.8e-5"], "--viscosity must be finite and > 0"),
    (["--axis", "xy"], "invalid choice: 'xy'"),
    (["--csv", "no/dir/c.csv"], "--csv no/dir/c.csv: folder no/dir does not exist"),
    (["--plot", "no/dir/c.png"], "--plot no/dir/c.png: folder no/dir does not exist"),
    (["--units", "inch"], "invalid choice: 'inch'"),
    (["--sample", "0", "1", "0", "1", "0", "1"], "reaches outside the packed bed"),
])
def test_curve_bad_input(argv, words, capsys):
    assert curve.main(["-q"] + argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("error: ") and words in err


def test_curve_plot_without_matplotlib(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert curve.main(["-q", "--plot", str(tmp_path / "c.png")]) == 2
    assert "pip install '.[plot]'" in capsys.readouterr().err


@pytest.mark.parametrize("argv, words", [
    (["--out", "no/dir/t.csv"], "--out no/dir/t.csv: folder no/dir does not exist"),
    (["--out", "t.csv", "--margin", "-0.01"], "--margin must be >= 0"),
    (["--out", "t.csv", "--units", "ft"], "invalid choice: 'ft'"),
    (["--out", "t.csv", "--sample", "0", "1", "0", "1", "0", "1"], "reaches outside"),
    ([], "the following arguments are required: --out"),
])
def test_throats_bad_input(argv, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert throatlist.main(["-q"] + argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and words in err
    assert not (tmp_path / "t.csv").exists()                     # nothing written


@pytest.mark.slow
def test_throats_units_mm(tmp_path):
    x = np.loadtxt(default_packing_path(), delimiter=",", skiprows=1)
    mm = tmp_path / "bed_mm.csv"
    np.savetxt(mm, x[:, :4] * 1e3, delimiter=",", header="x,y,z,r", comments="")
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert throatlist.main(["-q", "--out", str(a)]) == 0
    assert throatlist.main(["-q", str(mm), "--units", "mm", "--out", str(b)]) == 0
    np.testing.assert_allclose(np.loadtxt(b, delimiter=",", skiprows=1),
                               np.loadtxt(a, delimiter=",", skiprows=1), rtol=1e-7)


@pytest.mark.slow
@pytest.mark.parametrize("module", ["network.curve", "network.throatlist", "network.throats",
                                    "network.paths"])
def test_no_traceback_as_a_subprocess(module):
    run = subprocess.run([sys.executable, "-m", module, "--viscosity", "-1.8e-5", "--axis", "X",
                          "--units", "furlong"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and run.stdout == ""
    assert "Traceback" not in run.stderr and run.stderr.count("\n") == 1
