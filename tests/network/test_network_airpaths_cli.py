"""``python -m network.paths``: bad input is refused with exit status 2 and one line (no
traceback), and the ``--standin`` packing comes from the project's one random packer."""

import subprocess
import sys

import numpy as np
import pytest

from network.paths.__main__ import main
from network.paths._standin import STANDIN_POROSITY, standin_packing

SCENE = "network/data/soybean_default.csv"


@pytest.mark.parametrize("argv, words", [
    ([], "give PACKING or --standin"),
    (["no/such/packing.csv"], "no/such/packing.csv"),
    ([SCENE, "--entries", "0"], "n must be 1-10000"),
    ([SCENE, "--velocity", "0.013", "-0.02"], "--velocity must be finite and > 0"),
    (["--standin", "0.04", "0", "0.06"], "three box sides > 0"),
])
def test_bad_input_exits_2_with_one_line(argv, words, capsys):
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("error: ") and words in err


def test_bad_input_has_no_traceback():
    run = subprocess.run([sys.executable, "-m", "network.paths", "no/such/packing.csv"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2
    assert run.stdout == "" and "Traceback" not in run.stderr
    assert run.stderr.strip().count("\n") == 0


@pytest.mark.slow
def test_standin_packing_is_random_packing_at_the_bin_porosity():
    # as many 5.5-7.5 mm spheres as give porosity 0.408 in the box: n = 0.592 V / E[pi d^3/6]
    box = np.array([0.03, 0.03, 0.04])
    x, r = standin_packing(box, rng=3)
    d0, d1 = 5.5e-3, 7.5e-3
    mean_vol = np.pi / 6 * (d1**4 - d0**4) / (4 * (d1 - d0))
    assert r.size == round((1 - STANDIN_POROSITY) * box.prod() / mean_vol) == 145
    assert np.all((2 * r >= d0) & (2 * r <= d1))
    # its box [0, L] has the drawn spheres' volume at that porosity and the requested aspect
    assert x.min() > 0.0
    np.testing.assert_allclose((x + r[:, None]).max(axis=0), box, rtol=0.1)
    x2, r2 = standin_packing(box, rng=3)
    np.testing.assert_array_equal(x, x2)  # same seed, same packing
