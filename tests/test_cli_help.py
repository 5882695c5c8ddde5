"""Every command's ``--help`` explains every option.

Each CLI's ``main([])`` is run up to the moment it parses its arguments: the parser it built is
captured there, so the test reads the real parser of every command, whichever function builds it.
"""

from __future__ import annotations

import argparse
import importlib

import pytest

COMMANDS = ["network.solve", "network.curve", "network.paths", "network.report", "network.throatlist", "network.throats",
            "network.bench", "network.bin.__main__", "cache.precompute", "cache.lookup", "cache.bench", "throats.solve",
            "throats.bench", "dem.pack", "dem.vibrate", "dem.bench"]


class _Parsed(BaseException):
    """Raised in place of parsing; a BaseException so the CLIs' error handlers let it through."""


def _parser_of(module_name, monkeypatch):
    def grab(self, *args, **kwargs):
        raise _Parsed(self)

    monkeypatch.setattr(argparse.ArgumentParser, "parse_known_args", grab)
    module = importlib.import_module(module_name)
    if hasattr(module, "__path__"):     # a subpackage's command is its __main__
        module = importlib.import_module(module_name + ".__main__")
    with pytest.raises(_Parsed) as got:
        module.main([])
    return got.value.args[0]


@pytest.mark.parametrize("name", COMMANDS)
def test_every_option_has_help(name, monkeypatch):
    parser = _parser_of(name, monkeypatch)
    options = [a for a in parser._actions if a.dest != "help" and a.help != argparse.SUPPRESS]
    assert len(options) >= 2, name
    missing = [a.dest for a in options if not (a.help and len(a.help) > 12)]
    assert missing == [], f"{name}: options without help: {missing}"
