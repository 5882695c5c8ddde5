"""The thesis's numbers that ``python -m network.paths`` prints beside its own, and the
conventions under which the two compare.

:data:`THESIS` holds the thesis's soybean values (Tables 4.1-4.5: tortuosity, mean widths,
tetrahedra per path, branched-model and measured pressure drops), :data:`THESIS_DEPTH_M` the bed
depth its pressure drops are over, and :data:`CONVENTIONS` how the command's tortuosity, depths
and duplicate paths are defined; the command writes the last into its JSON.
"""

from __future__ import annotations

__all__ = ["CONVENTIONS", "THESIS", "THESIS_DEPTH_M"]

#: Thesis values (Tables 4.1-4.5) printed beside ours on a soybean bed (pressures: over 0.25 m).
THESIS = {
    "tortuosity": {"widest": 1.39, "narrowest": 1.40},
    "mean_width_mm": {"widest": (2.73, 2.91), "narrowest": (1.85, 2.00)},
    "tetrahedra": {"widest": (152, 162), "narrowest": (142, 154)},
    "branched_mfx3_average_pa": {"0.013": 2.74, "0.027": 5.65},
    "measured_pa": {"0.013": 2.44, "0.027": 6.80},
}
#: Bed depth of the thesis's measured and modelled pressure drops (Table 4.5), m.
THESIS_DEPTH_M = 0.25
CONVENTIONS = {
    "tortuosity": "Eq. 3.27 smoothed length over L0, the straight length along the flow axis "
                  "(thesis 3.4.2): the bed depth (centre span + mean diameter, Appendix D) for "
                  "built paths, which run floor to top; the path's own axial span for paths on "
                  "the tessellation, which start and end inside the bed",
    "depth": "pressure drops in the Table 4.5 layout are over --depth (default 0.25 m, as "
             "network.solve): ASABE D272 and Ergun as gradient x depth, the branched model as "
             "its drop along each path / the path's L0 x depth; the thesis's values are printed "
             "beside them only at 0.25 m and its velocities",
    "duplicates": "a path traced again from another entry (same kind, same tetrahedra) is "
                  "listed but counted once in the means and the branched model",
}
