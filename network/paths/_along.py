r"""Models evaluated along a path: the branched-path model of thesis 3.5.1 on the path's
tetrahedra (:func:`branched_path_pressure_drop`, :func:`branched_table`, Table 4.4 layout) and
the network-model pressure along a path on the tessellation (:func:`pressure_along_path`,
thesis 4.2.3).
"""

from __future__ import annotations

import numpy as np

from .._air import MU_AIR_PA_S
from ..pores import axis_index
from ._branched import BranchedResult, branched_pressure_drop, local_width
from ._geometry import EXIT_FACES, as_points, face_areas


def _path_faces(points, radii, path):
    """Faces of a path's tetrahedra (inlet face, then the three exits) as the model needs them.

    Returns full and open areas (m², (m, 4); NaN open areas as 0), face centroids (m, 4, 3)
    and tetrahedron centroids (m, 3), m.
    """
    x = as_points(points)
    tet = path.tetra_vertices
    if tet.shape[0] == 0:
        raise ValueError("path has no tetrahedra")
    faces = np.concatenate([tet[:, None, :3], tet[:, EXIT_FACES]], axis=1)  # (m, 4, 3)
    full, opened = face_areas(x, radii, faces)
    return full, np.nan_to_num(opened, nan=0.0), x[faces].mean(axis=2), x[tet].mean(axis=1)


def branched_path_pressure_drop(points, radii, path, *, superficial_velocity_m_s=None,
                                q0_m3_s=None, width="average", multiplier="MFx3",
                                branches="path", mu_pa_s=MU_AIR_PA_S) -> BranchedResult:
    r"""Branched-path model (thesis 3.5.1, Appendix F) along the tetrahedra of a path.

    Each tetrahedron is entered through its inlet face (``path.tetra_vertices[:, :3]``) and
    divides into its three other faces. The flow entering each tetrahedron is
    :math:`Q_0 = U S_0`, with :math:`U` the superficial velocity and :math:`S_0` the mean
    triangle area of the path's faces (Appendix F uses a constant
    :math:`S_0` = 17.613 mm², about the mean face area of a 6.5 mm packing), unless
    ``q0_m3_s`` is given.

    Parameters
    ----------
    points : (Ns, 3) array_like, m
    radii : (Ns,) array_like, m
    path : AirflowPath
    superficial_velocity_m_s : float, optional
    q0_m3_s : float, optional
        Overrides :math:`Q_0`.
    width : {'min', 'max', 'average'}
        Local flow-path width, see :func:`local_width`.
    multiplier : {'MFx3', 'MFx2'}
    branches : {'all', 'path'}
        See :func:`branched_pressure_drop`.
    mu_pa_s : float

    Returns
    -------
    BranchedResult
    """
    full, opened, cent, c_tet = _path_faces(points, radii, path)
    d = local_width(full, opened, width)
    if q0_m3_s is None:
        if superficial_velocity_m_s is None:
            raise ValueError("give superficial_velocity_m_s or q0_m3_s")
        q0_m3_s = float(superficial_velocity_m_s) * float(np.mean(full))
    return branched_pressure_drop(cent[:, 0], c_tet, cent[:, 1:], d[:, 0],
                                  d[:, 1:], path.exit_local, q0_m3_s, multiplier=multiplier,
                                  branches=branches, mu_pa_s=mu_pa_s)


def pore_pressure_array(n_pores, pore_ids, pressure_pa, labels=None):
    """Pressure of every tetrahedron from a network solution over a sample, (Np,) Pa.

    Parameters
    ----------
    n_pores : int
        Tetrahedra of the tessellation.
    pore_ids : (Ns,) int array_like
        Pore-body ids of the solved pores (``FlowResult.pore_ids``): tetrahedron ids, or group
        labels when tied tetrahedra were merged.
    pressure_pa : (Ns,) array_like, Pa
        Their pressures (``FlowResult.pressure_pa``).
    labels : (Np,) int array_like, optional
        Group label of each tetrahedron (``network.tie_groups``); None when not merged.

    Returns
    -------
    (Np,) ndarray, Pa; NaN outside the sample.
    """
    ids = np.asarray(pore_ids, dtype=np.intp)
    pr = np.asarray(pressure_pa, dtype=float)
    lab = np.arange(n_pores) if labels is None else np.asarray(labels, dtype=np.intp)
    body = np.full(max(int(lab.max()) + 1, int(ids.max()) + 1 if ids.size else 0), np.nan)
    body[ids] = pr
    return body[lab]


def pressure_along_path(graph, path, pore_pressure_pa, *, axis="z"):
    """Pressure of each tetrahedron on a Delaunay path, from a network solution (thesis 4.2.3).

    Parameters
    ----------
    graph : FaceGraph
    path : AirflowPath
        A path on the tessellation (method 'delaunay' or 'graph').
    pore_pressure_pa : (Np,) array_like, Pa
        Pressure per pore (NaN where the solver left a pore out).

    Returns
    -------
    position_m : (n,) ndarray, m
        Tetrahedron centroid coordinate along ``axis``.
    pressure_pa : (n,) ndarray, Pa
    """
    p = np.asarray(pore_pressure_pa, dtype=float)
    if p.shape != (graph.n_pores,):
        raise ValueError(f"pore_pressure_pa must have shape ({graph.n_pores},), got {p.shape}")
    if np.any(path.pores < 0):
        raise ValueError("the path is not on the tessellation (method 'build'); trace it with "
                         "method='delaunay' or kind 'maximin'/'shortest'")
    ax = axis_index(axis)
    pos = graph.points[graph.pore_vertices[path.pores]].mean(axis=1)[:, ax]
    return pos, p[path.pores]


def branched_table(points, radii, path, *, velocities_m_s=(0.013, 0.027),
                   widths=("max", "min", "average"), multipliers=("MFx3", "MFx2"),
                   branches="path", mu_pa_s=MU_AIR_PA_S):
    """Branched-model pressure drops of one path in the layout of thesis Table 4.4, Pa.

    Face areas are computed once and reused for every combination.

    Returns
    -------
    dict
        ``table[width][multiplier][f"{velocity:g}"] -> float`` (Pa), plus ``"q0_per_u_m2"``
        (the :math:`S_0` that multiplies the velocity) and ``"branches"``.
    """
    full, opened, cent, c_tet = _path_faces(points, radii, path)
    s0 = float(np.mean(full))
    out = {"q0_per_u_m2": s0, "branches": branches}
    for w in widths:
        d = local_width(full, opened, w)
        out[w] = {}
        for m in multipliers:
            out[w][m] = {}
            for u in velocities_m_s:
                res = branched_pressure_drop(cent[:, 0], c_tet, cent[:, 1:], d[:, 0], d[:, 1:],
                                             path.exit_local, float(u) * s0, multiplier=m,
                                             branches=branches, mu_pa_s=mu_pa_s)
                out[w][m][f"{u:g}"] = res.total_pa
    return out

