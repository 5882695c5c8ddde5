"""One airflow path and its measures (:class:`AirflowPath`), assembled from its tetrahedra."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..pores import axis_index
from ._branched import equivalent_diameter
from ._geometry import EXIT_FACES, face_areas, path_length, smoothed_length, turning_angles

@dataclasses.dataclass(frozen=True)
class AirflowPath:
    """One airflow path and its measures.

    Attributes
    ----------
    kind : str
        'widest' | 'narrowest' | 'maximin' | 'shortest'.
    method : str
        'build' (thesis construction), 'delaunay' (step-increment on the tessellation) or
        'graph' (optimal path on the tessellation).
    entry_xy : (2,) ndarray, m
        Entry point on the floor (coordinates of the two axes normal to the flow axis).
    axis : str
    status : str
        'ok' (reached the top), 'stuck' (no way on), 'max-steps'.
    tetra_vertices : (n, 4) int ndarray
        Sphere indices of the n tetrahedra, inlet face first (columns 0-2), apex last.
    exit_local : (n,) int ndarray
        Exit face of each tetrahedron as a row of :data:`EXIT_FACES`.
    points : (n + 1, 3) ndarray, m
        Centroids of the entry face and of every exit face: the path polyline.
    widths_m : (n,) ndarray, m
        Width of each exit face, Eq. 3.24 with its open area.
    length_m, smoothed_length_m : float, m
        Polyline length; Eq. 3.27.
    depth_m : float, m
        Bed depth the tortuosity is relative to.
    turning_angles_deg : (n - 1,) ndarray, degrees
    pores : (n,) int ndarray
        Delaunay pores (methods 'delaunay' and 'graph'; -1 for 'build').
    n_relaxed, n_backtracks : int
        Steps taken under a relaxed rule (see the tracer); steps taken back.
    """

    kind: str
    method: str
    entry_xy: np.ndarray
    axis: str
    status: str
    tetra_vertices: np.ndarray
    exit_local: np.ndarray
    points: np.ndarray
    widths_m: np.ndarray
    length_m: float
    smoothed_length_m: float
    depth_m: float
    turning_angles_deg: np.ndarray
    pores: np.ndarray
    n_relaxed: int = 0
    n_backtracks: int = 0

    @property
    def n_tetrahedra(self):
        return int(self.tetra_vertices.shape[0])

    @property
    def tortuosity_raw(self):
        """Path length over bed depth."""
        return self.length_m / self.depth_m

    @property
    def tortuosity(self):
        """Smoothed path length (Eq. 3.27) over bed depth (thesis 3.4.2)."""
        return self.smoothed_length_m / self.depth_m

    @property
    def tortuosity_span(self):
        """Path length over the path's own extent along the axis (>= 1).

        Paths on the tessellation start and end up to :data:`END_BAND_DIAMETERS` inside the
        bed, so their thesis tortuosity (over the bed depth) undercounts; this one does not.
        """
        ext = float(np.ptp(self.points[:, axis_index(self.axis)])) if self.points.size else 0.0
        return self.length_m / ext if ext > 0 else float("nan")

    @property
    def mean_width_m(self):
        return float(np.nanmean(self.widths_m)) if self.widths_m.size else float("nan")

    @property
    def bottleneck_width_m(self):
        return float(np.nanmin(self.widths_m)) if self.widths_m.size else float("nan")

    def summary(self):
        """Scalars of the path, JSON-ready."""
        ta = self.turning_angles_deg
        return {
            "kind": self.kind, "method": self.method, "axis": self.axis, "status": self.status,
            "entry_xy_m": [float(v) for v in self.entry_xy],
            "n_tetrahedra": self.n_tetrahedra, "length_m": self.length_m,
            "smoothed_length_m": self.smoothed_length_m, "depth_m": self.depth_m,
            "tortuosity_raw": self.tortuosity_raw, "tortuosity": self.tortuosity,
            "tortuosity_span": self.tortuosity_span, "mean_width_m": self.mean_width_m,
            "bottleneck_width_m": self.bottleneck_width_m,
            "turning_below_30deg": float(np.mean(ta < 30.0)) if ta.size else float("nan"),
            "n_relaxed": self.n_relaxed, "n_backtracks": self.n_backtracks,
        }


def path_record(points, radii, kind, method, entry_xy, axis, status, tetra, exit_local,
                 depth, *, pores=None, n_relaxed=0, n_back=0, angle_rule="eq3.25",
                 exit_open_m2=None):
    """Assemble an :class:`AirflowPath` from its tetrahedra (inlet face first)."""
    pts_all = np.asarray(points, dtype=float)
    tetra = np.asarray(tetra, dtype=np.intp).reshape(-1, 4)
    exit_local = np.asarray(exit_local, dtype=np.intp).reshape(-1)
    n = tetra.shape[0]
    if n:
        exit_tri = np.take_along_axis(tetra, EXIT_FACES[exit_local], axis=1)
        pts = np.concatenate([pts_all[tetra[:1, :3]].mean(axis=1),
                              pts_all[exit_tri].mean(axis=1)])
        if exit_open_m2 is None:
            _, exit_open_m2 = face_areas(pts_all, radii, exit_tri)
        widths = equivalent_diameter(np.nan_to_num(exit_open_m2, nan=0.0))
    else:
        pts = np.zeros((0, 3))
        widths = np.zeros(0)
    return AirflowPath(
        kind=kind, method=method, entry_xy=np.asarray(entry_xy, dtype=float), axis=axis,
        status=status, tetra_vertices=tetra, exit_local=exit_local, points=pts,
        widths_m=widths,
        length_m=path_length(pts) if n else 0.0,
        smoothed_length_m=smoothed_length(pts, rule=angle_rule) if n else 0.0,
        depth_m=float(depth), turning_angles_deg=turning_angles(pts) if n else np.zeros(0),
        pores=np.full(n, -1, dtype=np.intp) if pores is None else np.asarray(pores, np.intp),
        n_relaxed=int(n_relaxed), n_backtracks=int(n_back),
    )

