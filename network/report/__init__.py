"""``python -m network.report``: the engineer's report of a grain bed.

Examples
--------
    python -m network.report --grain wheat --depth 3 --diameter 6   # bundled wheat bed
    python -m network.report --grain corn --depth 5 --diameter 8    # the bin's beds (corn's set)
    python -m network.report --grain soybean --depth 3 --diameter 6 --fan fan.csv --html r.html
    python -m network.report --grain wheat --porosity 0.41 --packing bed.csv --json r.json
    python -m network.report --grain wheat --seed 2        # packs a new bed (dem.pack, minutes)

The inertial resistance curve (vertical z and horizontal x) of a packing, with ASABE D272 and
Ergun beside it and the fits of :func:`network.flow.fit_curve`; the porosity band (d ln(ΔP/L)/dε
computed by packing and solving neighbouring porosities, :mod:`network.report.band`); the
system curve of a bin and, with ``--fan``, its operating point (:mod:`network.report.system`).
Given a bin (``--diameter`` with ``--depth``), a grain's rain-filled bed set is solved and
integrated over the depth in Janssen's stress (:mod:`network.report.binbeds`).
The porosity reported is the grain's measured loose-fill porosity, ``--porosity``, or the
packing's own, moved along the band's slope (:mod:`network.report.porosity`); ``--seed`` or a
porosity away from the bundled bed's packs a new bed with ``dem.pack``
(:mod:`network.report.bed`).
Figures go to ``report_<grain>/`` unless ``--plot-dir``/``--no-figures`` say otherwise.
The library entry is :func:`build_report` with a :class:`ReportOptions`; the command is
:mod:`network.report.cli`. Exit 0 done, 1 a solve failed, 2 bad input: one ``error:`` line
(docs/cli.md, docs/report.md).
"""

from __future__ import annotations

from .build import build_report
from .cli import build_parser, main, print_report
from .options import ReportOptions, grain_key

__all__ = ["ReportOptions", "build_parser", "build_report", "grain_key", "main", "print_report"]
