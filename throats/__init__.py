r"""grainflow.throats: dimensionless conductance Q* of triangular pore throats.

A throat is the face shared by two Delaunay tetrahedra of sphere centres, given by the radii
``[r1, r2, r3]`` and side lengths ``[l12, l13, l23]`` (columns of the CSV
``r1,r2,r3,l12,l13,l23``).  Its open cross-section is the triangle minus the three disks;
with lengths scaled by the mean radius r̄ the flow solves −∇²u* = 1, u* = 0 on the disk arcs,
∂u*/∂n = 0 on the triangle-edge gaps, and Q* = ∫u* dA* (thesis Eq. 3.40–3.42).  The
dimensional conductance is g = Q* r̄⁴/(μL), formed by ``network``, not here.

Public functions
----------------
canonical_form, contact_type
    Scale/permutation/mirror-invariant form (units of r̄); contact type 'a'-'d' (Fig. 3.17).
open_area, triangle_area, triangle_vertices
    Exact open area (also for overlapping disks and disks covering the triangle); the triangle.
validate_throats, as_throats
    Row checks ``(ok_mask, messages)``; shape check at the door (two float (N, 3) arrays).
shape_factor_qstar, deep_overlap
    Fast Q* estimate c_t A² G (Patzek & Silin 2001) fitted per contact type, over 1e6
    throats/s; median error about 20 % against FE (``docs/throats-shape-factor.md``); the rows
    with a deep overlap (two spheres of one grain) that take their own constants.
section_ratio, section_fem, section_area_perimeter, shape_factor_ratio
    Sections with more disks than the three vertex disks (other spheres of the vertices'
    grains cutting the plane): the flow rate relative to the three-disk section by the
    distance-squared estimate (the shape-factor form for narrow sections), Q by finite
    elements, exact open area and wetted perimeter.
solve_fem, ThroatSolution, SOLVER_VERSION
    Q* by finite elements (gmsh + scikit-fem), batch, ``rtol``-driven, with an error estimate;
    the version string is bumped whenever results could change.

Command line: ``python -m throats.solve`` (one throat as JSON, or a CSV of throats,
``--method fem|shape-factor``); ``python -m throats.bench`` (time per throat against error).

Method (closing rule for passages narrower than 0.01 r̄, curved quadratic gmsh triangles,
Lagrange P3/P4, the error estimate, and what each costs) in
``docs/throats-method.md``; modules, lowest first: ``_geometry``, ``_boundary``, ``_area``,
``_shape_factor``, ``_mesh``, ``_trimesh``, ``_solve``, ``_multidisk``.
"""

from ._area import open_area
from ._geometry import (as_throats, canonical_form, contact_type, triangle_area, triangle_vertices,
                        validate_throats)
from ._multidisk import (NARROW_FRACTION, section_area_perimeter, section_fem, section_ratio,
                         shape_factor_ratio, sub_triangle_centroids)
from ._shape_factor import deep_overlap, shape_factor_qstar
from ._solve import SOLVER_VERSION, ThroatSolution, solve_fem

__all__ = ["SOLVER_VERSION", "as_throats", "ThroatSolution", "canonical_form", "contact_type",
           "deep_overlap", "open_area", "section_area_perimeter", "section_fem", "section_ratio",
           "NARROW_FRACTION", "shape_factor_ratio", "sub_triangle_centroids",
           "shape_factor_qstar", "solve_fem", "triangle_area", "triangle_vertices",
           "validate_throats"]
