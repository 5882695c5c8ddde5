"""Bad input to every command is refused before any work with exit 2 and one line that names
it, and no input file changes: templates in the wrong unit or with spheres inside spheres,
outputs that would overwrite an input or each other, beds too small for a sample, spheres that
overlap into one body under separate grain ids, option values in the wrong form."""

import hashlib

import pytest

from dem import pack as dem_pack
from dem.templates import read_template


def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _one_error(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: "), err
    return err[0]


# ---------------------------------------------------------------- grain templates
def test_a_template_in_metres_read_in_mm_says_so(tmp_path, capsys):
    t = tmp_path / "kernel.csv"
    t.write_text("x,y,z,r\n-0.001,0,0,0.0012\n0.001,0,0,0.0012\n")      # 4.4 mm, in metres
    before = _digest(t)
    with pytest.raises(ValueError, match=r"the grain is 0.0044 mm across read in mm "
                                         r"\(--template-units mm\): a template written in "
                                         r"metres\? give --template-units m"):
        read_template(t, units="mm")
    assert read_template(t, units="m").extent_m.max() == pytest.approx(4.4e-3, rel=2e-3)
    rc = dem_pack.main(["--scene", "box", "--grain", str(t), "--out", str(tmp_path / "o.csv")])
    assert rc == 2 and "give --template-units m" in _one_error(capsys)
    assert _digest(t) == before and not (tmp_path / "o.csv").exists()


@pytest.mark.parametrize("rows, words", [
    ("0,0,0,1\n0,0,0,1\n", "row 3: the sphere lies inside the sphere of row 2 (coincident"),
    ("0,0,0,1\n0.2,0,0,0.5\n1.5,0,0,1\n", "row 3: the sphere lies inside the sphere of row 2"),
    ("0,0,0,0.5\n1,0,0,1\n0.2,0,0,2\n", "row 2: the sphere lies inside the sphere of row 4"),
])
def test_coincident_or_contained_template_spheres_are_refused(tmp_path, capsys, rows, words):
    t = tmp_path / "kernel.csv"
    t.write_text("x,y,z,r\n" + rows)
    with pytest.raises(ValueError, match=words.replace("(", r"\(")):
        read_template(t, units="mm")
    rc = dem_pack.main(["--scene", "box", "--grain", str(t), "--out", str(tmp_path / "o.csv")])
    err = _one_error(capsys)
    assert rc == 2 and words in err and f"--grain {t}" in err
