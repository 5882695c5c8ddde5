"""Re-derive the computed BCC/FCC Stokes permeabilities of network._references (coarse mesh).

The solver: Stokes flow in the 1/8 symmetry cell [0, a/2]^3 of SC/BCC/FCC arrays (all three
have mirror planes at x, y, z = 0 and a/2), Taylor-Hood P2/P1 (gmsh + scikit-fem), no slip on
the spheres, zero normal velocity on the lateral planes, a unit pressure drop as traction on
the planes normal to the flow (tangential velocity zero there); k = int u_x dV / (a/2)^2.
It is checked against Zick & Homsy (1982, Table 2, simple cubic) and then against the tables
STOKES_CELL_BCC / STOKES_CELL_FCC, which were made with the same code at h = 0.05a and 0.04a
and Richardson-extrapolated. At the coarse h = 0.08a used here the discretisation error is
+2.2 % to +2.6 % on SC, +3.8 % on BCC and +6.0 % on FCC (measured), hence the brackets.
"""

import numpy as np
import pytest

from network.validation import computed_lattice_permeability, lattice_permeability

gmsh = pytest.importorskip("gmsh")
skfem = pytest.importorskip("skfem")

_SITES = {"sc": [(0, 0, 0)], "bcc": [(0, 0, 0), (1, 1, 1)],
          "fcc": [(0, 0, 0), (1, 1, 0), (1, 0, 1), (0, 1, 1)]}


def _cell_mesh(kind, phi, h):
    L = 0.5
    r = (3 * phi / (4 * np.pi * len(_SITES[kind]))) ** (1 / 3)
    was_up = gmsh.isInitialized()       # throats/ may keep a gmsh session with its options
    if not was_up:
        gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("stokes_cell")
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        gmsh.option.setNumber("Mesh.RecombineAll", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 1)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
        occ = gmsh.model.occ
        box = occ.addBox(0, 0, 0, L, L, L)
        shifts = np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1])).T.reshape(-1, 3)
        centres = {tuple(np.round(np.array(b) * 0.5 + s, 9))
                   for b in _SITES[kind] for s in shifts}
        tools = [(3, occ.addSphere(*c, r)) for c in centres
                 if np.linalg.norm(np.clip(c, 0, L) - np.array(c)) < r]
        occ.cut([(3, box)], tools)
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeMin", h / 3)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)
        gmsh.model.mesh.generate(3)
        tags, xyz, _ = gmsh.model.mesh.getNodes()
        _, _, conn = gmsh.model.mesh.getElements(3)
    finally:
        gmsh.model.remove()
        if not was_up:
            gmsh.finalize()
    p = xyz.reshape(-1, 3)
    idx = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    idx[tags.astype(np.int64)] = np.arange(tags.size)
    t = idx[conn[0].reshape(-1, 4).astype(np.int64)]
    used = np.unique(t)
    remap = np.full(p.shape[0], -1)
    remap[used] = np.arange(used.size)
    return skfem.MeshTet(p[used].T, remap[t].T)


def _cell_permeability(kind, phi, h):
    from skfem import (Basis, BilinearForm, ElementTetP1, ElementTetP2, ElementVector,
                       FacetBasis, Functional, LinearForm, bmat, condense, solve)
    from skfem.helpers import ddot, div, grad
    L = 0.5
    m = _cell_mesh(kind, phi, h)
    ub = Basis(m, ElementVector(ElementTetP2()), intorder=4)
    pb = Basis(m, ElementTetP1(), intorder=4)
    A = BilinearForm(lambda u, v, w: ddot(grad(u), grad(v))).assemble(ub)
    B = BilinearForm(lambda u, q, w: -div(u) * q).assemble(ub, pb)
    K = bmat([[A, B.T], [B, None]], "csr")
    inlet = m.facets_satisfying(lambda x: np.isclose(x[0], 0.0), boundaries_only=True)
    fb = FacetBasis(m, ub.elem, facets=inlet, intorder=4)
    f = np.concatenate([LinearForm(lambda v, w: v[0]).assemble(fb), np.zeros(pb.N)])
    bf = m.boundary_facets()
    mid = m.p[:, m.facets[:, bf]].mean(axis=1)
    on = [np.isclose(mid[k], 0) | np.isclose(mid[k], L) for k in range(3)]
    sphere = ~(on[0] | on[1] | on[2])
    D = np.unique(np.concatenate([
        ub.get_dofs(facets=bf[sphere]).all(),
        ub.get_dofs(facets=bf[on[0]]).all(["u^2", "u^3"]),
        ub.get_dofs(facets=bf[on[1]]).all(["u^2"]),
        ub.get_dofs(facets=bf[on[2]]).all(["u^3"])]))
    x = solve(*condense(K, f, D=D))
    flux = Functional(lambda w: w["u"][0]).assemble(ub, u=ub.interpolate(x[:ub.N]))
    return flux / L**2


@pytest.mark.slow
def test_solver_reproduces_zick_homsy_simple_cubic():
    # Zick & Homsy (1982) Table 2, phi = 0.343: coarse mesh within +1 % .. +4 %
    k = _cell_permeability("sc", 0.343, 0.08)
    r = (3 * 0.343 / (4 * np.pi)) ** (1 / 3)
    ratio = k / lattice_permeability("sc", 0.343, r)
    assert 1.01 < ratio < 1.04


@pytest.mark.parametrize("kind, phi, upper", [("bcc", 0.5, 1.05), ("fcc", 0.55, 1.08)])
def test_computed_tables_rederived_on_a_coarse_mesh(kind, phi, upper):
    # coarse-mesh excess over the extrapolated table (FCC's narrower gaps converge slower:
    # measured +6.0 % at 0.08a, +2.0 % at 0.05a, +1.3 % at 0.04a)
    k = _cell_permeability(kind, phi, 0.08)
    ratio = k / computed_lattice_permeability(kind, phi)
    assert 1.01 < ratio < upper
