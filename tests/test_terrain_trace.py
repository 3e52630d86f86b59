"""The mesh-guided program's root tracing (splinevis.terrain.trace, the float64 twin of
glsl/lib/terrain/mesh_guided.glsl) against the independent DDA reference, and the bounds it relies on."""

import numpy as np
import pytest

from splinevis.terrain.hard_cases import high_relief
from splinevis.terrain.mesh_proxy import lifted_mesh, mesh_above, trace_bounds
from splinevis.terrain.model import TerrainSpline
from splinevis.terrain.raycast import raycast_terrain
from splinevis.terrain.trace import trace_first_root

SCHEMES = ["linear", "C0", "C1", "C2", "C2-cubic"]


def _rays(t, n, seed):
    """Rays at the terrain, steep to grazing (down to ~3 degrees), starting where they enter its box (no root lies
    before that)."""
    rng = np.random.default_rng(seed)
    x0, x1, y0, y1 = t.extent
    zlo, zhi = t.coefficients.min() + t.z_ref, t.coefficients.max() + t.z_ref
    target = np.column_stack([rng.uniform(x0, x1, n), rng.uniform(y0, y1, n), np.full(n, zlo)])
    d = rng.normal(size=(n, 3))
    d[:, 2] = -np.abs(d[:, 2]) * rng.uniform(0.05, 3.0, n)
    d /= np.linalg.norm(d, axis=1)[:, None]
    lo, hi = np.array([x0, y0, zlo - 1.0]), np.array([x1, y1, zhi + 1.0])
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (lo - target) / d, (hi - target) / d
        entry = np.where(np.abs(d) < 1e-12, -np.inf, np.minimum(a, b))
    back = entry.max(axis=1)  # the box entry (t <= 0); kept: rays entering through the top, above the surface
    top = entry.argmax(axis=1) == 2
    return (target + back[:, None] * d * (1 - 1e-12))[top], d[top]


@pytest.mark.parametrize("kind", ["crater", "cliff"])
@pytest.mark.parametrize("scheme", SCHEMES)
def test_tracing_finds_the_first_root(kind, scheme):
    t = TerrainSpline.from_heights(high_relief(kind, 33), scheme, spacing=(1.0, 1.0))
    o, d = _rays(t, 3000, 7)
    r = trace_first_root(t, o, d, max_steps=400)
    ref = raycast_terrain(t, o, d).t
    hit, ref_hit = r.state == "hit", np.isfinite(ref)
    # no step passes a root: every traced hit is the reference's first hit, to float64 rounding of t (the
    # rays' length is ~ the box's size, 200 here; roots are accepted at |g| <= 1e-12 of the heights)
    assert (hit <= ref_hit).all()
    assert np.abs(r.t[hit] - ref[hit]).max() <= 1e-8
    # a miss is one: leaving the box or the domain loses no root
    assert not ((r.state == "missed") & ref_hit).any()
    # rays that do not converge within the steps are the program's fallback cases: a few in a hundred at most
    assert (r.state == "capped").mean() <= 0.02
    assert hit.mean() >= 0.5


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("k", [1, 2])
def test_exit_bound_holds_over_the_lifted_mesh(scheme, k):
    # the tracing leaves a ray that rises higher than G above the spline: G must bound mesh - s everywhere
    t = TerrainSpline.from_heights(high_relief("crater", 33), scheme, spacing=(1.0, 1.0))
    m = lifted_mesh(t, k)
    G = trace_bounds(t, k)[..., 1]
    ncy, ncx = t.shape
    uv = np.random.default_rng(3).uniform(0.0, 1.0, (40_000, 2)) * (ncx, ncy)
    above = mesh_above(t, m, uv[:, 0], uv[:, 1])
    i = np.minimum(uv[:, 0].astype(int), ncx - 1)
    j = np.minimum(uv[:, 1].astype(int), ncy - 1)
    assert (above > 0).all() and (above <= G[j, i] * (1 + 1e-9)).all()


@pytest.mark.parametrize("scheme", SCHEMES)
def test_block_mesh_of_a_large_grid_lies_above_within_its_exit_bound(scheme, monkeypatch):
    # grids over MAX_MESH_CELLS are drawn with one mesh square per block of B x B cells: the mesh still lies
    # above the spline and within the exit bound G of every cell (Hessian bound for the C1 schemes, the block's
    # coefficient range for all)
    import splinevis.terrain.mesh_proxy as mp

    monkeypatch.setattr(mp, "MAX_MESH_CELLS", 100)
    t = TerrainSpline.from_heights(high_relief("crater", 65), scheme, spacing=(1.0, 1.0))
    m = lifted_mesh(t, 1)
    ncy, ncx = t.shape
    assert m.block == mp.mesh_block(t) > 1 and (len(m.gu) - 1) * (len(m.gv) - 1) <= 100
    G = trace_bounds(t, 1)[..., 1]
    uv = np.random.default_rng(4).uniform(0.0, 1.0, (40_000, 2)) * (ncx, ncy)
    above = mesh_above(t, m, uv[:, 0], uv[:, 1])
    i = np.minimum(uv[:, 0].astype(int), ncx - 1)
    j = np.minimum(uv[:, 1].astype(int), ncy - 1)
    assert (above > 0).all() and (above <= G[j, i] * (1 + 1e-9)).all()


@pytest.mark.parametrize("kind", ["crater", "cliff"])
def test_the_reference_solves_in_batches_the_same_hits_as_step_by_step(kind, monkeypatch):
    # raycast_terrain solves the candidate segments of several walk steps at once; each ray keeps its first
    # candidate with a root in the walk's order, so the hits equal those of solving every step alone, bit for bit
    from splinevis.terrain import raycast

    t = TerrainSpline.from_heights(high_relief(kind, 33), "C2", spacing=(1.0, 1.0))
    o, d = _rays(t, 30000, 3)
    batched = raycast_terrain(t, o, d)
    monkeypatch.setattr(raycast, "FLUSH_STEPS", 1)
    single = raycast_terrain(t, o, d)
    assert np.isfinite(batched.t).sum() > 500
    assert np.array_equal(batched.t, single.t, equal_nan=True)
    assert np.array_equal(batched.normals, single.normals, equal_nan=True)


def test_each_ray_hits_what_it_hits_cast_alone():
    # the walk keeps only the walking rays' rows (dropping stopped ones now and then) and solves the candidates of
    # many rays at once: neither may change a ray's float operations, so a ray cast alone gets the same bits
    t = TerrainSpline.from_heights(high_relief("cliff", 33), "C2", spacing=(1.0, 1.0))
    o, d = _rays(t, 4000, 5)
    d[::4, 2] = np.abs(d[::4, 2])  # a quarter turned up from where they enter the box: misses among the hits
    together = raycast_terrain(t, o, d)
    picked = np.random.default_rng(2).choice(len(o), 60, replace=False)
    assert np.isfinite(together.t[picked]).sum() > 20 and np.isnan(together.t[picked]).sum() > 0
    for k in picked:
        alone = raycast_terrain(t, o[k], d[k])
        assert np.array_equal(alone.t, together.t[k], equal_nan=True)
        assert np.array_equal(alone.normals, together.normals[k], equal_nan=True)
