"""python -m network.throatlist (and its contract name network.throats) as a new user: lossless
lengths, bad input exits 2 with one ``error:`` line and writes nothing, --help covers every
option."""

import numpy as np
import pytest

import network
from network import throatlist as throats_cli


@pytest.fixture(scope="module")
def bed(tmp_path_factory):
    path = tmp_path_factory.mktemp("bed") / "bed.csv"
    network.write_packing_csv(network.random_packing(150, rng=3, max_sweeps=300), path)
    return path


def test_writes_lengths_that_read_back_bit_for_bit(bed, tmp_path):
    out = tmp_path / "t.csv"
    assert throats_cli.main([str(bed), "--out", str(out), "--quiet"]) == 0
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    tess = network.tessellate(network.read_packing(bed))
    idx = rows[:, 6].astype(int)
    np.testing.assert_array_equal(rows[:, :6], np.c_[tess.throat_radii, tess.throat_sides][idx])
    assert out.read_text().splitlines()[0] == throats_cli.HEADER
    assert not list(tmp_path.glob("*.part"))


@pytest.mark.parametrize("argv, text", [
    (["{bed}", "--out", "{tmp}/nofolder/t.csv"], "does not exist"),
    (["{bed}", "--out", "{tmp}"], "folder"),
    (["{bed}", "--out", "{tmp}/t.csv", "--units", "inch"], "invalid choice: 'inch'"),
    (["{bed}"], "required: --out"),
    (["{tmp}/missing.csv", "--out", "{tmp}/t.csv"], "missing.csv"),
    (["{nan}", "--out", "{tmp}/t.csv"], "row 3: non-finite"),      # header = row 1
    (["{bed}", "--out", "{tmp}/t.csv", "--margin", "-1"], "--margin"),
    (["{bed}", "--out", "{tmp}/t.csv", "--sample", "0", "1", "0", "1", "0", "1"], "bed"),
])
def test_bad_input_exit_2_one_line_nothing_written(bed, tmp_path, capsys, argv, text):
    nan = tmp_path / "nan.csv"
    lines = bed.read_text().splitlines()
    nan.write_text("\n".join(lines[:2] + [lines[2].rsplit(",", 1)[0] + ",nan"] + lines[3:]))
    argv = [a.format(bed=bed, tmp=tmp_path, nan=nan) for a in argv]
    assert throats_cli.main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: ") and text in err[0], err
    assert not (tmp_path / "t.csv").exists() and not list(tmp_path.glob("*.part"))


def test_help_explains_every_option(capsys):
    with pytest.raises(SystemExit) as exc:
        throats_cli.main(["--help"])
    assert exc.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    for action in throats_cli.build_parser()._actions:
        if action.option_strings and action.dest != "help":
            assert action.help and action.option_strings[0] in text, action.dest
            shown = action.default not in (None, False)      # the formatter appends it
            assert shown or "default" in action.help or "required" in action.help, action.dest


def test_the_contract_name_is_the_same_command(bed, tmp_path, capsys):
    """``python -m network.throats`` (the throat-export contract's name) writes the same file
    and names itself in its error lines."""
    from network import throats

    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert throats_cli.main([str(bed), "--out", str(a), "--quiet"]) == 0
    assert throats.main([str(bed), "--out", str(b), "--quiet"]) == 0
    assert a.read_bytes() == b.read_bytes()
    capsys.readouterr()
    assert throats.main([str(bed), "--out", str(tmp_path / "no" / "c.csv")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ")
    assert throats.build_parser(throats.PROG).prog == "python -m network.throats"

