r"""grainflow.throats: dimensionless conductance Q* of triangular pore throats.

A throat is the face shared by two Delaunay tetrahedra of sphere centres, given by the radii
``[r1, r2, r3]`` and side lengths ``[l12, l13, l23]`` (columns of the CSV
``r1,r2,r3,l12,l13,l23``).  Its open cross-section is the triangle minus the three disks;
with lengths scaled by the mean radius r̄ the flow solves −∇²u* = 1, u* = 0 on the disk arcs,
∂u*/∂n = 0 on the triangle-edge gaps, and Q* = ∫u* dA* (thesis Eq. 3.40–3.42).  The
dimensional conductance is g = Q* r̄⁴/(μL), formed by ``network``, not here.

Public functions
----------------
canonical_form
    Scale/permutation/mirror-invariant form of a throat (units of r̄).
contact_type
    Contact type 'a' | 'b' | 'c' | 'd' (thesis Fig. 3.17).
open_area
    Exact open area, also for overlapping disks and disks covering the triangle.
validate_throats
    Row checks: ``(ok_mask, messages)``.
as_throats
    Shape check at the door: two float (N, 3) arrays.
triangle_vertices
    Planar vertex coordinates of the triangles.
triangle_area
    Triangle area from the sides (Heron, Kahan's stable form).
shape_factor_qstar
    Fast Q* estimate in the Patzek & Silin (2001) form c_t A² G, fitted per contact type
    (median error 21 %, 95th percentile 54 % against FE; over 1e6 throats/s).
solve_fem
    Q* by finite elements (gmsh + scikit-fem), batch, ``rtol``-driven, with an error
    estimate; returns a ``ThroatSolution``.
SOLVER_VERSION
    Version string of the numerical method (bumped whenever results could change).

Command line
------------
``python -m throats.solve``
    One throat (JSON) or a CSV of throats, ``--method fem|shape-factor``.
``python -m throats.bench``
    Time per throat against error for FE tolerances and the shape factor (table + JSON).

Method notes: passages narrower than 0.01 r̄ (tangent, overlapping or nearly touching disks)
are closed by short no-slip cuts (:mod:`throats._mesh`, error < 2e-5 measured); the FE solve
uses curved quadratic gmsh triangles and Lagrange P3/P4 (:mod:`throats._solve`).
"""

from ._geometry import (as_throats, canonical_form, contact_type, open_area, triangle_area,
                        triangle_vertices, validate_throats)
from ._shape_factor import shape_factor_qstar
from ._solve import SOLVER_VERSION, ThroatSolution, solve_fem

__all__ = ["SOLVER_VERSION", "as_throats", "ThroatSolution", "canonical_form", "contact_type", "open_area",
           "shape_factor_qstar", "solve_fem", "triangle_area", "triangle_vertices",
           "validate_throats"]
