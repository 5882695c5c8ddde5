"""The README's Python example is ``docs/examples/quickstart.py``, shown verbatim, and it runs.

As scikit-fem's docs/examples are, the example is a script a test runs and checks: the numbers it
prints obey Darcy's law and mass conservation, agree with Kozeny-Carman (d32, Sauter diameter)
within the spread that correlation has for random sphere packings, and are the bundled scene's
numbers the README quotes.
"""

import re
import runpy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "docs" / "examples" / "quickstart.py"


def python_blocks(markdown):
    """The fenced ```python blocks of a Markdown text, each as its text with a final newline."""
    return [m.group(1) for m in re.finditer(r"```python\n(.*?)```", markdown, re.DOTALL)]


def test_readme_shows_the_quickstart_verbatim():
    blocks = python_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    assert EXAMPLE.read_text(encoding="utf-8") in blocks


def test_python_blocks_finds_a_fenced_block():
    assert python_blocks("a\n```python\nx = 1\n```\nb\n```bash\nls\n```\n") == ["x = 1\n"]


@pytest.mark.slow
def test_quickstart_runs_and_its_numbers_hold(capsys):
    ns = runpy.run_path(str(EXAMPLE), run_name="__main__")
    out = capsys.readouterr().out
    res, packing, k_kc = ns["result"], ns["packing"], ns["k_kc"]

    assert packing.n == 3000
    # the inset window's porosity, where k is measured; the whole sample's 0.399 beside it
    # (network/data/README.md)
    assert abs(res.porosity - 0.394) < 0.001 and abs(res.porosity_sample - 0.399) < 0.001
    # Darcy: dP = mu U L / k over the bed depth, the identity the Stokes answer obeys
    darcy = res.viscosity_pa_s * res.velocity_m_s * res.depth_m / res.permeability_m2
    assert res.pressure_drop_pa == pytest.approx(darcy, rel=1e-12)
    assert res.check["ok"] and res.check["balance_error"] < 1e-8   # inflow = outflow
    assert 0.9 < res.permeability_m2 / k_kc < 1.1            # Kozeny-Carman on d32
    assert res.permeability_m2 == pytest.approx(4.2284e-8, rel=1e-4)   # the README's value
    assert "permeability     4.2284e-08 m2" in out
    assert "pressure drop    1.485 Pa over 0.25 m at 0.013 m/s" in out


def test_readme_indexes_every_docs_page_and_names_no_missing_one():
    """The README's documentation index lists each page of docs/, and every docs/ path the README
    names exists."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    pages = {p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").glob("*.md")}
    named = set(re.findall(r"docs/[A-Za-z0-9_./-]+\.(?:md|py|png)", readme))
    assert pages - named == set()
    assert {p for p in named if not (ROOT / p).exists()} == set()
