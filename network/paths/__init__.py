r"""Airflow paths through the tetrahedra of a packing (thesis 3.4-3.6, 4.1.2-4.1.3; Appendices
D-F): path geometry, the face graph, path construction, walks, the branched-path model, plots.

A path is a chain of tetrahedra from the bed floor to the bed top, represented by the
centroids of the faces it crosses (thesis Fig. 3.9). Kinds and methods:

``'widest'`` / ``'narrowest'``, method ``'build'`` (:func:`build_paths`, the thesis's own
    construction, 3.4.1): tetrahedra built sphere by sphere upward, leaving each through the
    open exit face of largest (smallest) open area :math:`S_f` (Eq. 3.23); :class:`BuildRules`
    names the readings of its ambiguous steps (docs/airpaths.md).
``'widest'`` / ``'narrowest'``, method ``'delaunay'`` (:func:`walk_paths`): the same exit rule
    walked on the Delaunay tessellation, whose tetrahedra are fixed.
``'maximin'`` (:func:`maximin_paths`): the optimal widest path on the tessellation, whose
    narrowest face is as wide as possible (maximin bottleneck), the shortest such path.
``'shortest'`` (:func:`shortest_paths`): the shortest chain of face centroids (Dijkstra).

Per path: length, tetrahedra count, tortuosity raw and smoothed (Eqs. 3.25-3.27), turning
angles and local widths :math:`d_f = 2\sqrt{S_f/\pi}` (Eq. 3.24); the branched-path model of
3.5.1 along it (:func:`branched_path_pressure_drop`, :func:`branched_table`) and the network
pressure along it (:func:`pressure_along_path`).

Modules: ``_geometry`` (angles, lengths, smoothing, face areas), ``_faces`` (the face graph,
slivers, entry points), ``_record`` (:class:`AirflowPath`), ``_build`` (the thesis's
construction), ``_walks`` (walks and graph paths, :func:`trace_paths`), ``_branched`` (the
branched-path model, docs/airpaths-branched.md), ``_along`` (models along a path), ``_plots``;
``__main__`` is the command ``python -m network.paths``, with ``_standin`` (its ``--standin``
packing) and ``_reference`` (the thesis's values it prints beside its own).
"""

from ._along import (branched_path_pressure_drop, branched_table, pore_pressure_array,
                     pressure_along_path)
from ._branched import (MULTIPLIERS, WIDTHS, BranchedResult, branched_pressure_drop,
                        branching_multiplier, equivalent_diameter, laminar_pipe_dp, local_width)
from ._build import BuildRules, build_paths, eq323_area, eq323_negative
from ._faces import (END_BAND_DIAMETERS, MIN_QUALITY, FaceGraph, entry_faces, face_graph,
                     passable_pores, pore_quality, random_entry_points)
from ._geometry import (EXIT_FACES, OMEGA_A, OMEGA_B_DEG, bed_depth, face_areas,
                        interior_angles, path_length, smoothed_length, smoothing_factor,
                        turning_angles)
from ._plots import plot_paths
from ._record import AirflowPath
from ._walks import PATH_KINDS, maximin_paths, shortest_paths, trace_paths, walk_paths

__all__ = ["END_BAND_DIAMETERS", "EXIT_FACES", "MIN_QUALITY", "MULTIPLIERS", "OMEGA_A",
           "OMEGA_B_DEG", "PATH_KINDS", "WIDTHS", "AirflowPath", "BranchedResult", "BuildRules",
           "FaceGraph",
           "bed_depth", "branched_path_pressure_drop", "branched_pressure_drop",
           "branched_table", "branching_multiplier", "build_paths", "entry_faces",
           "eq323_area", "eq323_negative", "equivalent_diameter", "face_areas", "face_graph",
           "interior_angles", "laminar_pipe_dp", "local_width", "maximin_paths",
           "passable_pores", "path_length", "plot_paths", "pore_pressure_array", "pore_quality",
           "pressure_along_path", "random_entry_points", "shortest_paths", "smoothed_length",
           "smoothing_factor", "trace_paths", "turning_angles", "walk_paths"]
