"""Test-wide settings."""

import pytest


@pytest.fixture(autouse=True, scope="session")
def _private_throat_table(tmp_path_factory):
    """No test reads or writes the user's Q* table (``~/.cache/grainflow/throats.sqlite``).

    ``cache.default_db_path()`` honours ``$GRAINFLOW_CACHE_DB``; pointing it at a fresh path
    makes every default-table lookup start from the shipped grid alone, so results do not
    depend on what earlier runs on this machine stored (measured: six stored simple-cubic
    shapes moved a table-only SC permeability by 3 %).
    """
    mp = pytest.MonkeyPatch()
    mp.setenv("GRAINFLOW_CACHE_DB", str(tmp_path_factory.mktemp("cache") / "throats.sqlite"))
    # nor the user's reachable porosity ranges of the grown fill (~/.cache/grainflow/reach)
    mp.setenv("GRAINFLOW_REACH_CACHE", str(tmp_path_factory.mktemp("reach")))
    yield
    mp.undo()
