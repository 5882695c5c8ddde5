"""dem command lines follow the project's exit codes: 0 done, 1 computation failed
(unstable, not converged, interrupted), 2 bad input."""

import json

import pytest

from dem import bench, pack, vibrate


def test_unconverged_packing_is_written_marked_and_exits_1(tmp_path, capsys):
    out = tmp_path / "bed.csv"
    code = pack.main(["--scene", "box", "--size", "0.03", "0.03", "--height", "0.03",
                      "--max-steps", "300", "--out", str(out), "--quiet", "--seed", "1"])
    assert code == 1
    summary = json.loads(out.with_suffix(".json").read_text())
    assert summary["converged"] is False
    err = capsys.readouterr().err
    assert "error: not at equilibrium: stage" in err and "Traceback" not in err


def test_bad_input_exits_2(tmp_path, capsys):
    code = pack.main(["--scene", "box", "--size", "0.03", "--height", "0.03", "--out",
                      str(tmp_path / "b.csv")])
    assert code == 2
    assert "box needs 2 size value(s)" in capsys.readouterr().err
    assert not (tmp_path / "b.csv").exists()


def test_ctrl_c_exits_1_with_one_line_and_writes_nothing(tmp_path, capsys, monkeypatch):
    """Ctrl-C during the packing: one ``interrupted:`` line, exit 1, no packing (it is written
    whole at the end) and no traceback."""
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(pack, "pack_bed", interrupted)
    out = tmp_path / "b.csv"
    code = pack.main(["--scene", "box", "--size", "0.03", "0.03", "--height", "0.03",
                      "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and len(err) == 1 and err[0].startswith("interrupted: "), err
    assert not list(tmp_path.iterdir())


@pytest.mark.slow
def test_grain_beds_take_the_users_step_limit(tmp_path, monkeypatch, capsys):
    """--max-steps reaches the grain packer as given (it was silently capped at 60 000, so a
    corn bed that settles in ~100 000 steps could not be packed); the default stays 60 000;
    0 is refused (exit 2)."""
    seen = []

    def fake_pack_grains(*a, **kw):
        seen.append(kw["max_steps"])
        raise KeyboardInterrupt          # stop before any work: exit 1, nothing written

    monkeypatch.setattr(pack, "pack_grains", fake_pack_grains)
    base = ["--scene", "box", "--grain", "soybean", "--fill", "grow", "--out", str(tmp_path / "g.csv"), "--quiet"]
    assert pack.main([*base, "--max-steps", "240000"]) == 1
    assert pack.main(base) == 1
    assert seen == [240000, pack.GRAIN_MAX_STEPS] and pack.GRAIN_MAX_STEPS == 60000
    assert pack.main([*base, "--max-steps", "0"]) == 2
    assert "--max-steps must be >= 1" in capsys.readouterr().err
    assert not (tmp_path / "g.csv").exists()


@pytest.mark.parametrize("argv, words", [
    (["--settle-steps", "0"], "--settle-steps must be 1 to"),
    (["--mass-scale", "0.5"], "--mass-scale must be >= 1"),
    (["--steady-window", "-1"], "--steady-window must be finite and >= 0"),
    (["--record-every", "0"], "--record-every must be finite and > 0"),
    (["--duration", "nan"], "--duration must be finite and > 0"),
    (["--snapshots", "0.1", "-2"], "--snapshots must be times >= 0 s"),
])
def test_vibrate_names_the_bad_run_option_before_any_work(argv, words, tmp_path, capsys):
    out = tmp_path / "vib"
    assert vibrate.main(["no_such_bed.csv", "--amplitude", "0.001", "--out", str(out)] + argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err
    assert not out.exists()



@pytest.mark.parametrize("main, argv, named", [
    (pack.main, ["--scene", "box", "--grain", "wheat", "--drop-height", "abc"],
     "error: argument --drop-height: invalid float value: 'abc'"),
    (vibrate.main, ["b.csv", "--intensity", "abc"], "error: argument --intensity: invalid float value: 'abc'"),
    (pack.main, ["--scene", "box", "--grain", "wheat", "--fill", "grow", "--mass-scale", "0"],
     "error: --mass-scale 0: must be finite and >= 1"),
    (pack.main, ["--scene", "box", "--size", "0.03", "0.03", "--height", "0.03", "--mass-scale", "-1"],
     "error: --mass-scale -1: must be finite and >= 1"),
    (pack.main, ["--scene", "box", "--grain", "wheat", "--mass-scale", "nan"],
     "error: --mass-scale nan: must be finite and >= 1"),
    (pack.main, ["--scene", "box", "--grain", "wheat", "--stress", "20000", "20000.0001"],
     "error: --stress 20000 and 20000.0001 Pa both write out_20kPa.csv"),
    (pack.main, ["--scene", "box", "--grain", "wheat", "--fill", "spout", "--spout-diameter", "0.05"],
     "error: --spout-diameter 0.05 m is wider than the container (0.04 m)"),
    (pack.main, ["--scene", "box", "--grain", "wheat", "--stress", "0", "1e9"],
     "error: --stress 1e+09 Pa: must be finite, >= 0 and <= 1e+06 Pa"),
    (pack.main, ["--scene", "box", "--grain", "wheat", "--depth", "1000", "--bin-diameter", "1000"],
     "error: --depth 1000 m of a 1000 m bin: Janssen's stress there, about 49"),
    (bench.main, ["--pour", "10", "--pour-stress", "1e9", "--json", "b.json"],
     "error: --pour-stress must be finite, > 0 and <= 1e+06 Pa"),
])
def test_bad_option_values_are_one_error_line_exit_2_nothing_written(main, argv, named, tmp_path, capsys,
                                                                       monkeypatch):
    """A value the parser or the checks refuse: exit 2, one ``error:`` line naming the option and
    the value (not the usage block, not an internal name), and no file written."""
    monkeypatch.chdir(tmp_path)
    rc = main(argv + ["--out", "out.csv", "--quiet"] if main is pack.main else argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].startswith(named), err
    assert list(tmp_path.iterdir()) == []
