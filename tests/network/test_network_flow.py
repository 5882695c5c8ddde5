"""Assembly, condensation and the pyamg solve (STYLE item 7)."""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from network.flow import (apply_pressure_bc, assemble_laplacian, boundary_flows,
                           solve_fixed_pressure, solve_pressure)


def grid_network(nx, ny, nz):
    """Pores on an nx*ny*nz grid, throats along the grid edges (i < j)."""
    idx = np.arange(nx * ny * nz).reshape(nx, ny, nz)
    conns = np.vstack([
        np.column_stack([idx[:-1].ravel(), idx[1:].ravel()]),
        np.column_stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()]),
        np.column_stack([idx[:, :, :-1].ravel(), idx[:, :, 1:].ravel()]),
    ])
    return idx, conns


def test_laplacian_rows_sum_to_zero_and_symmetric():
    _, c = grid_network(3, 4, 5)
    g = np.random.default_rng(0).random(len(c))
    A = assemble_laplacian(60, c, g)
    np.testing.assert_allclose(A.sum(axis=1), 0, atol=1e-14)
    assert abs(A - A.T).max() == 0


def test_series_chain_exact():
    """Conductances in series: Q = dP / sum(1/g) (the resistor-chain closed form)."""
    g = np.array([1.0, 2.0, 4.0, 0.5, 3.0])
    conns = np.column_stack([np.arange(5), np.arange(1, 6)])
    p, info, check = solve_fixed_pressure(6, conns, g, [0], [5], p_in=7.0, p_out=2.0)
    q_exact = 5.0 / np.sum(1 / g)
    np.testing.assert_allclose(check["q_in"], q_exact, rtol=1e-12)
    np.testing.assert_allclose(check["q_out"], q_exact, rtol=1e-12)
    # pressure drops across each throat are q/g
    np.testing.assert_allclose(-np.diff(p), q_exact / g, rtol=1e-10)


def test_uniform_grid_permeability_exact():
    """Cubic network, spacing a, conductance g: Darcy k = mu g / a exactly."""
    nx, ny, nz, a, g0, mu = 6, 5, 9, 1e-3, 2.5e-9, 1.8e-5
    idx, c = grid_network(nx, ny, nz)
    p, info, check = solve_fixed_pressure(idx.size, c, np.full(len(c), g0),
                                          idx[:, :, 0].ravel(), idx[:, :, -1].ravel())
    assert check["ok"] and info.converged
    area, length = nx * ny * a * a, (nz - 1) * a
    k = mu * check["q_in"] * length / (area * 1.0)
    np.testing.assert_allclose(k, mu * g0 / a, rtol=1e-10)


def test_condensation_formula():
    _, c = grid_network(2, 2, 3)
    g = np.arange(1.0, len(c) + 1)
    A = assemble_laplacian(12, c, g)
    A_ii, b_i, free, p = apply_pressure_bc(A, np.zeros(12), [0, 11], [3.0, -1.0])
    dense = A.toarray()
    np.testing.assert_allclose(A_ii.toarray(), dense[np.ix_(free, free)])
    np.testing.assert_allclose(b_i, -dense[np.ix_(free, [0, 11])] @ [3.0, -1.0])
    assert np.all(np.linalg.eigvalsh(A_ii.toarray()) > 0)          # SPD after condensation


@pytest.mark.parametrize("contrast", [1.0, 1e6, 1e12])
def test_amg_matches_spsolve_under_contrast(contrast):
    """pyamg SA-PCG converges and agrees with a direct solve for conductance contrasts to 1e12."""
    rng = np.random.default_rng(11)
    idx, c = grid_network(14, 14, 14)
    g = 10.0 ** (rng.uniform(0, np.log10(contrast), len(c))) if contrast > 1 else np.ones(len(c))
    inlet, outlet = idx[:, :, 0].ravel(), idx[:, :, -1].ravel()
    p, info, check = solve_fixed_pressure(idx.size, c, g, inlet, outlet)
    assert info.converged
    assert check["balance_error"] <= 1e-8 and check["max_pore_residual"] <= 1e-8
    p_ref, _, check_ref = solve_fixed_pressure(idx.size, c, g, inlet, outlet, solver=spsolve)
    # the mass-balance tolerance (1e-8 of the flow per pore) pins a pore's pressure only to
    # about 1e-8 q_in / G_i: at contrast 1e12 the pores joined by conductances 1e-5 of the
    # largest come to within 9e-7 of the direct solve (RCM order; 2e-9 in the tessellation's),
    # the others and every throat flow far closer
    np.testing.assert_allclose(p, p_ref, rtol=0, atol=1e-7 if contrast <= 1e6 else 1e-5)
    np.testing.assert_allclose(check["q_in"], check_ref["q_in"], rtol=1e-7)
    q, q_ref = check["throat_flow"], check_ref["throat_flow"]
    assert np.abs(q - q_ref).max() <= 1e-7 * np.abs(q_ref).max()


def test_non_convergence_reported_not_raised():
    idx, c = grid_network(10, 10, 10)
    g = np.ones(len(c))
    A = assemble_laplacian(idx.size, c, g)
    A_ii, b_i, free, _ = apply_pressure_bc(A, np.zeros(idx.size), idx[:, :, 0].ravel(), 1.0)
    x, info = solve_pressure(A_ii, b_i + 1.0, maxiter=1, tol=1e-14)
    assert not info.converged and info.iterations <= 2


def test_boundary_flows_sign_convention():
    q, q_in, q_out, net = boundary_flows(np.array([[0, 1]]), np.array([2.0]),
                                         np.array([3.0, 1.0]), [0], [1])
    assert q[0] == 4.0 and q_in == 4.0 and q_out == 4.0


@pytest.mark.parametrize("bad, exc, match", [
    (dict(throat_conns=np.array([[0, 5]]), g=[1.0]), ValueError, "out of range"),
    (dict(throat_conns=np.array([[0, 1]]), g=[-1.0]), ValueError, ">= 0"),
    (dict(throat_conns=np.array([[0, 1]]), g=[np.nan]), ValueError, "finite"),
    (dict(throat_conns=np.array([[0.0, 1.0]]), g=[1.0]), TypeError, "integers"),
    (dict(throat_conns=np.array([0, 1]), g=[1.0]), ValueError, r"\(Nt, 2\)"),
])
def test_assemble_rejects_bad_input(bad, exc, match):
    with pytest.raises(exc, match=match):
        assemble_laplacian(3, **bad)


def test_isolated_free_pore_is_an_error():
    A = sp.csr_array(np.array([[0.0]]))
    with pytest.raises(ValueError, match="prune"):
        solve_pressure(A, np.array([1.0]))


def test_amg_solver_builds_once_and_keeps_evolution():
    """AMGSolver: a second right-hand side reuses the hierarchy (no setup time, one
    build); under 1e12 contrast the evolution hierarchy, once built, is kept for later solves."""
    from network.flow import AMGSolver
    idx, c = grid_network(10, 10, 10)
    A = assemble_laplacian(idx.size, c, np.ones(len(c)))
    A_ii, b_i, free, _ = apply_pressure_bc(A, np.zeros(idx.size), idx[:, :, [0, -1]].ravel(),
                                           np.r_[np.ones(100), np.zeros(100)])
    amg = AMGSolver(A_ii)
    x1, i1 = amg.solve(b_i)
    x2, i2 = amg.solve(2 * b_i)
    assert amg.builds == 1 and i1.setup_s > 0 and i2.setup_s == 0.0
    np.testing.assert_allclose(x2, 2 * x1, rtol=1e-8)
    x_ref, _ = solve_pressure(A_ii, b_i)
    # solve_pressure is one AMGSolver solve: the same answer to the CG tolerance (1e-10)
    np.testing.assert_allclose(x1, x_ref, rtol=1e-8)
    rng = np.random.default_rng(11)
    idx, c = grid_network(14, 14, 14)
    g = 10.0 ** rng.uniform(0, 12, len(c))
    A = assemble_laplacian(idx.size, c, g)
    A_ii, b_i, _, _ = apply_pressure_bc(A, np.zeros(idx.size), idx[:, :, [0, -1]].ravel(),
                                        np.r_[np.ones(196), np.zeros(196)])
    amg = AMGSolver(A_ii)
    _, i1 = amg.solve(b_i)
    assert i1.converged and amg.strength == "evolution" and amg.builds == 2
    _, i2 = amg.solve(b_i + 1e-3 * rng.standard_normal(b_i.size))
    assert i2.converged and amg.builds == 2 and i2.iterations < i1.iterations


def test_amg_setup_is_reproducible_and_leaves_numpy_random_alone():
    """pyamg's spectral-radius estimate starts from np.random.rand: the setup seeds NumPy's
    legacy generator for itself, so two hierarchies of one matrix give the same solution to the
    bit (the parallel continuation chains compare CG counts across setups), and the caller's
    global generator continues where it was."""
    from network.flow import AMGSolver
    rng = np.random.default_rng(5)
    idx, c = grid_network(12, 12, 12)
    A = assemble_laplacian(idx.size, c, 10.0 ** rng.uniform(0, 3, len(c)))
    A_ii, b_i, _, _ = apply_pressure_bc(A, np.zeros(idx.size), idx[:, :, [0, -1]].ravel(),
                                        np.r_[np.ones(144), np.zeros(144)])
    np.random.seed(123)
    expected_next = np.random.rand()
    np.random.seed(123)
    x1, i1 = AMGSolver(A_ii).solve(b_i)
    assert np.random.rand() == expected_next
    np.random.rand(7)                        # another global state for the second setup
    x2, i2 = AMGSolver(A_ii).solve(b_i)
    assert i1.iterations == i2.iterations and np.array_equal(x1, x2)


@pytest.mark.slow
def test_finest_smoothing_weight_is_the_gershgorin_bound():
    """The finest prolongator is smoothed with rho = max_i sum_j |a_ij| / a_ii: 2 for
    a condensed grid Laplacian, never below the largest eigenvalue of D^-1 A; a matrix that is
    not diagonally dominant (bound > 2) keeps pyamg's estimate. Both solve to the tolerance."""
    from network.flow import AMGSolver
    from network.flow._amg import gershgorin_bound
    rng = np.random.default_rng(3)
    idx, c = grid_network(8, 8, 8)
    A = assemble_laplacian(idx.size, c, 10.0 ** rng.uniform(0, 3, len(c)))
    A_ii, b_i, _, _ = apply_pressure_bc(A, np.zeros(idx.size), idx[:, :, [0, -1]].ravel(),
                                        np.r_[np.ones(64), np.zeros(64)])
    dense = A_ii.toarray()
    top = np.linalg.eigvals(dense / np.diag(dense)[:, None]).real.max()
    bound = gershgorin_bound(A_ii)
    assert abs(bound - 2.0) <= 1e-14 and top <= bound
    amg = AMGSolver(A_ii)
    x, info = amg.solve(b_i)
    assert amg.rho == bound and info.converged
    assert amg._ml.levels[0].A.rho == bound      # what pyamg's smoother read (its rho cache)
    np.testing.assert_allclose(x, spsolve(sp.csc_array(A_ii), b_i), rtol=1e-7)
    # SPD, not diagonally dominant: M^T M + I of a random sparse M
    M = sp.random_array((300, 300), density=0.02, random_state=4) + sp.eye_array(300)
    S = sp.csr_array(M.T @ M + sp.eye_array(300))
    assert gershgorin_bound(S) > 2.0
    amg = AMGSolver(S)
    b = rng.standard_normal(300)
    y, info = amg.solve(b)
    assert amg.rho is None and info.converged
    np.testing.assert_allclose(S @ y, b, atol=1e-8 * np.linalg.norm(b))
