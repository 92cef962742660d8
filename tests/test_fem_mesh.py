"""Method "fem": the graded quadtree mesh, the array assembly, the nested dissection and the condensation.

Run: python -m pytest tests/test_fem_mesh.py -q
"""
from __future__ import annotations

from types import SimpleNamespace as NS

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from railtherm_fem.condense import nested_dissection
from railtherm_fem.coupled import FemProblem, clear_cache, solve_fem
from railtherm_fem.elastic import ElasticStrip, node_adjacency, stiffness_matrix
from railtherm_fem.mesh import graded_strip_mesh

L, H, W, HS = 0.08, 0.04, 1.25e-3, 1e-3 / 40


def edges_of(t):
    e = np.sort(np.hstack([t[[0, 1]], t[[1, 2]], t[[2, 0]]]), axis=0)
    return np.unique(e, axis=1, return_counts=True)


@pytest.fixture(scope="module", params=[1.0, 2.0, 8.0])  # 1.0 needs the 2:1 balancing pass
def strip(request):
    return graded_strip_mesh(L, H, W, HS, grading=request.param), request.param


def test_mesh_conforming_and_covers_the_strip(strip):
    """Every edge in one or two triangles, the single ones on the outer boundary; areas sum to L H."""
    sm, _ = strip
    p, t = sm.mesh.p, sm.mesh.t
    x, y = p[0, t], p[1, t]
    area = 0.5 * np.abs((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]))
    assert abs(area.sum() / (L * H) - 1) < 1e-12
    assert area.min() > 0.05 * HS ** 2
    e, count = edges_of(t)
    assert set(np.unique(count)) <= {1, 2}
    b = e[:, count == 1]
    mid = 0.5 * (p[:, b[0]] + p[:, b[1]])
    tol = 1e-12
    on_boundary = (np.abs(mid[1]) < tol) | (np.abs(mid[1] + H) < tol) | (np.abs(np.abs(mid[0]) - L / 2) < tol)
    assert on_boundary.all()
    assert abs(np.hypot(*(p[:, b[0]] - p[:, b[1]])).sum() - 2 * (L + H)) < 1e-12
    assert np.allclose(np.diff(sm.x_window), HS, rtol=1e-9) and abs(sm.x_window[0] + sm.x_window[-1]) < 1e-12


def test_mesh_graded_and_balanced(strip):
    """Element size <= distance to the window / (grading - 1/2) (or the finest size); neighbours within 2:1.

    A leaf cell was left whole because its distance exceeds grading x its diagonal; a triangle lies in
    its cell (diagonal >= longest edge), so its centroid is at least (grading - 1/2) x its longest edge away.
    """
    sm, g = strip
    p, t = sm.mesh.p, sm.mesh.t
    lengths = np.stack([np.hypot(*(p[:, t[i]] - p[:, t[(i + 1) % 3]])) for i in range(3)])
    diam = lengths.max(axis=0)
    c = p[:, t].mean(axis=1)
    dist = np.hypot(np.maximum(np.abs(c[0]) - W, 0.0), c[1])
    finest = 2 * np.hypot(HS, HS)
    assert np.all(diam <= np.maximum(finest, dist / (g - 0.5)) * (1 + 1e-9))
    # neighbours across an edge: measured at most 1.71 (a level jump of 2 would leave a hanging node,
    # caught by the conformity test)
    e = np.sort(np.hstack([t[[0, 1]], t[[1, 2]], t[[2, 0]]]), axis=0)
    key = e[0].astype(np.int64) * p.shape[1] + e[1]
    tri = np.tile(np.arange(t.shape[1]), 3)
    o = np.argsort(key, kind="stable")
    k, tr = key[o], tri[o]
    pair = np.nonzero(k[1:] == k[:-1])[0]
    ratio = diam[tr[pair]] / diam[tr[pair + 1]]
    assert np.max(np.maximum(ratio, 1 / ratio)) <= 2.0


def test_stiffness_matches_scikit_fem():
    """Array assembly = skfem.asm of the same bilinear form (plane strain + moving-frame term)."""
    from skfem import Basis, BilinearForm, ElementTriP1, ElementVector, asm
    from skfem.helpers import ddot, eye, sym_grad, trace

    sm = graded_strip_mesh(0.02, 0.01, 1e-3, 1e-4, grading=3.0)
    lam, mu, rv2 = 1.2e11, 8.2e10, 3e9
    basis = Basis(sm.mesh, ElementVector(ElementTriP1()), intorder=1)

    @BilinearForm
    def form(u, v, w):
        eu = sym_grad(u)
        sig = 2.0 * mu * eu + lam * eye(trace(eu), 2)
        return ddot(sig, sym_grad(v)) - rv2 * (u.grad[0][0] * v.grad[0][0] + u.grad[1][0] * v.grad[1][0])

    K0 = asm(form, basis).tocsr()
    K1 = stiffness_matrix(sm.mesh.p, sm.mesh.t, lam, mu, rv2)
    assert abs(K0 - K1).max() <= 1e-12 * abs(K0).max()
    assert np.array_equal(basis.nodal_dofs, np.vstack([2 * np.arange(sm.mesh.nvertices), 2 * np.arange(sm.mesh.nvertices) + 1]))


def test_stiffness_rigid_body_modes():
    """Translations and the infinitesimal rotation produce no force (rho V^2 = 0)."""
    sm = graded_strip_mesh(0.02, 0.01, 1e-3, 1e-4, grading=3.0)
    K = stiffness_matrix(sm.mesh.p, sm.mesh.t, 1.2e11, 8.2e10)
    x, y = sm.mesh.p
    for ux, uy in ((np.ones_like(x), 0 * x), (0 * x, np.ones_like(x)), (-y, x)):
        u = np.empty(2 * x.size)
        u[0::2], u[1::2] = ux, uy
        assert np.abs(K @ u).max() <= 1e-12 * abs(K).max() * np.abs(u).max()


def test_nested_dissection_is_a_permutation_and_cuts_fill():
    """The ordering is a permutation of the nodes and its LU fill is far below the natural order's."""
    sm = graded_strip_mesh(0.02, 0.01, 1e-3, 1e-4, grading=4.0)
    n = sm.mesh.nvertices
    adj = node_adjacency(sm.mesh.t, n)
    nodes = np.arange(n)
    order = nested_dissection(adj, sm.mesh.p, nodes)
    assert np.array_equal(np.sort(order), nodes)
    A = (adj + sp.identity(n) * 10.0).tocsc()  # SPD, the mesh's pattern
    fill = {}
    for name, perm in (("nd", order), ("natural", nodes)):
        lu = spla.splu(A[perm][:, perm].tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                       options=dict(SymmetricMode=True))
        fill[name] = lu.L.nnz + lu.U.nnz
    assert fill["nd"] < 0.5 * fill["natural"], fill


def test_compliance_is_the_schur_complement_inverse():
    """Compliance read from the trailing factor block = inverse of K_ww - K_wi K_ii^-1 K_iw (dense check)."""
    sm = graded_strip_mesh(0.01, 0.005, 5e-4, 1e-4, grading=2.0)
    es = ElasticStrip(sm, 1.2e11, 8.2e10)
    n = es.ndofs
    fixed = np.zeros(n, bool)
    fixed[es.fixed_dofs] = True
    w = np.concatenate([es.node_dofs[0, sm.window], es.node_dofs[1, sm.window]])
    inner = np.setdiff1d(np.nonzero(~fixed)[0], w)
    K = es.K.toarray()
    S = K[np.ix_(w, w)] - K[np.ix_(w, inner)] @ np.linalg.solve(K[np.ix_(inner, inner)], K[np.ix_(inner, w)])
    C = np.linalg.inv(S)
    assert np.abs(es.compliance - C).max() <= 1e-9 * np.abs(C).max()


def test_mechanics_reused_between_solves():
    """Same geometry and materials: the mechanics is built once; results identical to a cold solve."""
    mat = NS(shear_modulus=82e9, poisson_ratio=0.28, density=7850.0, specific_heat=450.0, conductivity=50.0,
             thermal_expansion=12e-6, bulk_temperature=0.0, rigid=False)
    F = 3e5
    prob = lambda xi: FemProblem(radius=0.5, rail=mat, wheel=mat, speed=10.0, normal_force=F, friction=0.3,
                                 creepage=xi, thermal=False, level=0)
    clear_cache()
    cold = solve_fem(prob(-2e-4))
    warm = solve_fem(prob(-2e-4))
    assert warm.strip is cold.strip
    assert np.array_equal(warm.contact.traction, cold.contact.traction)
    clear_cache()
    again = solve_fem(prob(-2e-4))
    assert again.strip is not cold.strip
    assert np.array_equal(again.contact.traction, cold.contact.traction)


def _skfem_thermal_load(es, theta, depth, intorder=12):
    """The thermal load assembled directly by scikit-fem's LinearForm (the reference of ElasticStrip's)."""
    from skfem import Basis, ElementTriP1, ElementVector, LinearForm, asm
    mesh = es.strip.mesh
    elems = np.nonzero((-mesh.p[1, mesh.t]).min(axis=0) < depth)[0]
    beta = es.alpha * (3.0 * es.lam + 2.0 * es.mu)
    basis = Basis(mesh, ElementVector(ElementTriP1()), elements=elems, intorder=intorder)

    @LinearForm
    def load(v, w):
        return beta * theta(w.x[0], -w.x[1]) * (v.grad[0][0] + v.grad[1][1])
    f = asm(load, basis)
    f[es.fixed_dofs] = 0.0
    return f


def test_thermal_load_and_its_operator_equal_scikit_fem_assembly():
    """The kept-quadrature thermal load, and the grid operator E (E(theta) = load of theta's bilinear
    interpolant), equal scikit-fem's assembly of the same form, for two fields in turn on one grid (the
    second is not served the first's values) and for a second depth (its own quadrature)."""
    from railtherm_fem.coupled import _interpolator
    from railtherm_fem.thermal import thermal_grid
    sm = graded_strip_mesh(L, H, W, HS, grading=4.0)
    es = ElasticStrip(sm, 1.2e11, 8.2e10, 7850.0, 10.0, 12e-6)
    g = thermal_grid(W, HS, -0.3 * L, 0.3 * L, HS / 4, 2e-3, 1.1, 1.1)
    X, Z = np.meshgrid(g.x, g.z, indexing="ij")
    for depth in (2e-3, 1e-3):
        E = es.thermal_load_operator(g, depth=depth)
        for values in (50.0 * np.exp(-Z / 2e-4 - (X / W) ** 2), 20.0 * np.exp(-Z / 5e-4) * (X < 0)):
            theta = _interpolator(g, values)
            ref = _skfem_thermal_load(es, theta, depth)
            scale = np.abs(ref).max()
            assert scale > 0
            assert np.abs(es.thermal_load(theta, depth=depth) - ref).max() <= 1e-12 * scale
            assert np.abs(E(values) - ref).max() <= 1e-12 * scale


def _steel(**kw):
    return NS(**{**dict(shear_modulus=82e9, poisson_ratio=0.28, density=7850.0, specific_heat=450.0,
                        conductivity=50.0, thermal_expansion=12e-6, bulk_temperature=0.0, rigid=False), **kw})


def test_mechanics_cache_is_keyed_by_every_input_and_bounded(monkeypatch):
    """Another level, grading, material, speed or radius builds its own mechanics (never another's); the
    cache keeps at most CACHE_SIZE entries and CACHE_BYTES in all (nothing when one entry is larger)."""
    from railtherm_fem import coupled
    base = dict(radius=0.5, rail=_steel(), wheel=_steel(), speed=10.0, normal_force=3e5, friction=0.3,
                creepage=-2e-4, thermal=False, level=0)
    clear_cache()
    ref = solve_fem(FemProblem(**base)).strip
    for change in (dict(level=1), dict(grading=4.0), dict(rail=_steel(shear_modulus=80e9)),
                   dict(wheel=_steel(rigid=True)), dict(speed=20.0), dict(radius=0.45)):
        assert solve_fem(FemProblem(**{**base, **change})).strip is not ref, change
        assert len(coupled._MECH_CACHE) <= coupled.CACHE_SIZE
    assert sum(m.nbytes for m in coupled._MECH_CACHE.values()) <= coupled.CACHE_BYTES
    monkeypatch.setattr(coupled, "CACHE_BYTES", 1)
    clear_cache()
    solve_fem(FemProblem(**base))
    assert len(coupled._MECH_CACHE) == 0
