"""Airflow paths through the pore network: path geometry, the face graph, path construction,
walks, the thesis's branched-path model and path plots (thesis 3.6)."""

from ._branched import (MULTIPLIERS, WIDTHS, BranchedResult, branched_pressure_drop,
                        branching_multiplier, equivalent_diameter, laminar_pipe_dp, local_width)
from ._paths import (EXIT_FACES, PATH_KINDS, AirflowPath, FaceGraph, bed_depth,
                     branched_path_pressure_drop, branched_table, build_paths, entry_faces,
                     face_areas, face_graph, interior_angles, maximin_paths, passable_pores,
                     path_length, pore_pressure_array, pore_quality, pressure_along_path,
                     random_entry_points, shortest_paths, smoothed_length, smoothing_factor,
                     trace_paths, turning_angles, walk_paths)
from ._plots import plot_paths

__all__ = ["EXIT_FACES", "MULTIPLIERS", "PATH_KINDS", "WIDTHS", "AirflowPath", "BranchedResult",
           "FaceGraph", "bed_depth", "branched_path_pressure_drop", "branched_pressure_drop",
           "branched_table", "branching_multiplier", "build_paths", "entry_faces",
           "equivalent_diameter", "face_areas", "face_graph", "interior_angles",
           "laminar_pipe_dp", "local_width", "maximin_paths", "passable_pores", "path_length",
           "plot_paths", "pore_pressure_array", "pore_quality", "pressure_along_path",
           "random_entry_points", "shortest_paths", "smoothed_length", "smoothing_factor",
           "trace_paths", "turning_angles", "walk_paths"]
