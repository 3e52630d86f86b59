// Ray casting a quartic terrain spline [Reis2008] through a min/max hierarchy, per fragment.
//
// Proxy: one box around the whole terrain, rasterized with front faces culled. Each fragment's ray is
// taken to index space (u, v in spline cells, z = height relative to the reference height) and walks a
// quadtree of (min, max) coefficient bounds, front to back (the hierarchical equivalent of the occlusion
// sets of [Reis2008, sec. VII]): a block whose bounds the ray's height range over the block misses is
// skipped whole; otherwise the walk descends; a cell (level 0) is tested triangle by triangle exactly as
// one patch of programs/analytic_patch.glsl (clip, restrict by blossoming, first root, [Reis2008, sec. V]).
// The frame cost grows with the number of blocks a ray visits (~ log of the grid size for most rays), not
// with the patch count. The float64 reference is splinevis.terrain.raycast (a plain cell-by-cell DDA).
#include "lib/core/raycast.glsl"
#include "lib/core/table.glsl"
#include "lib/simplex/bb_triangle.glsl"
#include "lib/simplex/graph_patch.glsl"
#include "lib/simplex/quartic_unrolled.glsl"
#ifdef SV_TERRAIN_MESH
// the mesh-guided build (proxy="mesh"): the full walk below becomes sv_surface_hit_full, the fallback of
// lib/terrain/mesh_guided.glsl (included at the end), which defines sv_surface_hit
#define sv_surface_hit sv_surface_hit_full
#endif

// VTK declares the samplers of the textures set on the actor, both tables (lib/core/table.glsl):
// sv_terrain_coef (8 texels per cell, cells row after row: T0's 15 then T1's 15 coefficients, 2 zeros) and
// sv_terrain_minmax (the hierarchy, level after level: level L's block (bi, bj) at texel
// sv_level_offset[L] + bj * sv_level_width[L] + bi, .rg = (min, max)).
uniform int sv_level_offset[16];   // ints: offsets pass 2^24 texels on a 3600^2 grid, where floats skip
uniform int sv_level_width[16];    // odd values (a block's bounds read from its neighbour: lines of pinholes)
uniform int sv_top_level;
uniform vec2 sv_ncells;            // (ncx, ncy)
uniform vec2 sv_index_scale;       // u = sv_index_scale.x * x_mc + sv_index_shift.x (likewise v)
uniform vec2 sv_index_shift;
uniform vec2 sv_zrange;            // coefficient range, model z
uniform int sv_max_steps;          // hierarchy steps per ray before giving up
uniform int sv_newton_iterations;
uniform float sv_scalar_offset;    // reference height: hit.scalar is the physical height (colormaps)

vec2 sv_block_minmax(int level, ivec2 b) {
    return sv_table_texel(sv_terrain_minmax, sv_level_offset[level] + b.y * sv_level_width[level] + b.x).rg;
}

// A coefficient table over 1 GiB is split by rows into up to 4 textures (sv_terrain_coef, sv_terrain_coef1,
// ...; SV_ROWS_PER_TEXTURE rows each): a cell's 8 texels share a row, so they share a texture.
vec4 sv_coef_texel(ivec2 a) {
#ifdef SV_TERRAIN_SPLIT
    int piece = a.y / SV_ROWS_PER_TEXTURE;
    ivec2 b = ivec2(a.x, a.y - piece * SV_ROWS_PER_TEXTURE);
#ifdef SV_TERRAIN_SPLIT4
    if (piece == 3) return texelFetch(sv_terrain_coef3, b, 0);
#endif
#ifdef SV_TERRAIN_SPLIT3
    if (piece == 2) return texelFetch(sv_terrain_coef2, b, 0);
#endif
    if (piece == 1) return texelFetch(sv_terrain_coef1, b, 0);
    return texelFetch(sv_terrain_coef, b, 0);
#else
    return texelFetch(sv_terrain_coef, a, 0);
#endif
}

void sv_load_cell(ivec2 c, out float b0[15], out float b1[15]) {
    float w[32];
    // 8 texels per cell starting at a multiple of 8: one table row (lib/core/table.glsl)
    ivec2 first = sv_table_address(8 * (c.y * int(sv_ncells.x) + c.x));
    for (int q = 0; q < 8; ++q) {
        vec4 v = sv_coef_texel(first + ivec2(q, 0));
        w[4 * q] = v.x; w[4 * q + 1] = v.y; w[4 * q + 2] = v.z; w[4 * q + 3] = v.w;
    }
    for (int q = 0; q < 15; ++q) {
        b0[q] = w[q];
        b1[q] = w[15 + q];
    }
}

// Barycentric coordinates of cell-local (u, v): T0 = [(0,0),(1,0),(1,1)], T1 = [(0,0),(1,1),(0,1)].
vec3 sv_cell_bary(vec2 p, int tri) {
    return tri == 0 ? vec3(1.0 - p.x, p.x - p.y, p.y) : vec3(1.0 - p.y, p.x, p.y - p.x);
}

// Cells and triangles are clipped with a margin of 2^-16 of a cell (about 8 ulps of cell-local
// coordinates of size ~30): a root on a shared edge, which float32 rounding could push out of both
// neighbours' segments (a crack), is then found by at least one of them. Inside the margin the
// triangle's polynomial is its own extension, which meets the neighbour continuously (C0 at least).
const float SV_CELL_MARGIN = 1.52587890625e-05;

// First hit (t in [ta, tb]) of the cell-local ray o + t d with triangle `tri`; SV_NO_HIT if none
// (t may be negative: rays start on the far side of the proxy, see lib/core/raycast.glsl).
// The ray is rebased to the segment's start before its barycentric coordinates are taken: o is far from the
// cell (the ray starts on the far side of the proxy, up to the grid's size away), and lam_o + t lam_d with
// |lam_o| ~ that distance sums to 1 only within ~u times it, which scales the whole restricted polynomial:
// on a flat plateau 90 m above the reference height that offset exceeded the slab and the ray missed
// (pinholes on plateaus and valley floors). From a point in the cell the coordinates sum to 1 within a few u.
float sv_triangle_hit(float b[15], int tri, vec3 o, vec3 d, float ta, float tb, float margin) {
    vec3 start = o + ta * d;
    vec3 lo = sv_cell_bary(start.xy, tri);
    vec3 ld = sv_cell_bary(d.xy, tri) - sv_cell_bary(vec2(0.0), tri);
    float s = sv_graph_patch_hit(b, lo, ld, start.z, d.z, 0.0, tb - ta, margin, sv_newton_iterations);
    return s == SV_NO_HIT ? SV_NO_HIT : ta + s;
}

// Where the index-space ray P0 + t D leaves the rectangle [lo, hi] across x and across y: (tx, ty), 3e38 for an
// axis the ray runs along. Cells, hierarchy blocks and the mesh-guided tracing's pieces all step by it.
vec2 sv_rect_exit(vec3 P0, vec3 D, vec2 lo, vec2 hi) {
    return vec2(abs(D.x) < 1e-30 ? 3.0e38 : ((D.x > 0.0 ? hi.x : lo.x) - P0.x) / D.x,
                abs(D.y) < 1e-30 ? 3.0e38 : ((D.y > 0.0 ? hi.y : lo.y) - P0.y) / D.y);
}

// The index-space ray P0 + t D from tmin clipped to the terrain's box (cells x height range): [t, t_end], false
// when the ray misses it.
bool sv_clip_to_box(vec3 P0, vec3 D, float tmin, out float t, out float t_end) {
    t = tmin;
    t_end = 3.0e38;
    vec3 blo = vec3(0.0, 0.0, sv_zrange.x);
    vec3 bhi = vec3(sv_ncells, sv_zrange.y);
    for (int k = 0; k < 3; ++k) {
        if (abs(D[k]) < 1e-30) {
            if (P0[k] < blo[k] || P0[k] > bhi[k]) return false;
        } else {
            float ta = (blo[k] - P0[k]) / D[k];
            float tb = (bhi[k] - P0[k]) / D[k];
            t = max(t, min(ta, tb));
            t_end = min(t_end, max(ta, tb));
        }
    }
    return t <= t_end;
}

// Normal, scalar, uv and curvature of a hit at t_hit in cell cell_hit (index-space ray P0 + t D).
void sv_terrain_fill_hit(vec3 ro, vec3 rd, vec3 P0, vec3 D, float t_hit, ivec2 cell_hit, inout SvHit hit) {
    hit.t = t_hit;
    hit.pos = ro + t_hit * rd;
    vec3 P = P0 + t_hit * D;
    vec2 local = P.xy - vec2(cell_hit);
    int tri = local.y > local.x ? 1 : 0;
    float b0[15];
    float b1[15];
    sv_load_cell(cell_hit, b0, b1);
    float b[15];
    for (int q = 0; q < 15; ++q) b[q] = tri == 0 ? b0[q] : b1[q];
    vec3 l = sv_cell_bary(local, tri);
    float f;
    vec3 a;
    float dd[6];
#ifdef SV_TERRAIN_LEGACY
    sv_tri_quartic_jet(b, l, f, a, dd);
#else
    sv_tri_quartic_jet_unrolled(b, l, f, a, dd);  // constant indices: the generic steps cost ~1/8 of a frame here
#endif
    vec3 du = sv_cell_bary(vec2(1.0, 0.0), tri) - sv_cell_bary(vec2(0.0), tri);
    vec3 dv = sv_cell_bary(vec2(0.0, 1.0), tri) - sv_cell_bary(vec2(0.0), tri);
    float fx = 4.0 * dot(du, a) * sv_index_scale.x;
    float fy = 4.0 * dot(dv, a) * sv_index_scale.y;
    hit.normal = vec3(-fx, -fy, 1.0);
    hit.scalar = f + sv_scalar_offset;
    hit.uv = P.xy / sv_ncells;
#ifdef SV_OUT_CURVATURE
    float fxx = sv_tri_quartic_d2(dd, du, du) * sv_index_scale.x * sv_index_scale.x;
    float fxy = sv_tri_quartic_d2(dd, du, dv) * sv_index_scale.x * sv_index_scale.y;
    float fyy = sv_tri_quartic_d2(dd, dv, dv) * sv_index_scale.y * sv_index_scale.y;
    float g = 1.0 + fx * fx + fy * fy;
    hit.curvature = vec2(((1.0 + fy * fy) * fxx - 2.0 * fx * fy * fxy + (1.0 + fx * fx) * fyy) / (2.0 * pow(g, 1.5)),
                         (fxx * fyy - fxy * fxy) / (g * g));
#endif
}

#ifdef SV_DEBUG_RAYMARCH
// The reference ray march of the benchmarks (debug="raymarch"; benchmarks/bench_profile.py): the same ray in
// index space and the same box clip, then sv_march_steps fixed steps through the box (no early exit), each
// reading the coefficient texel of the cell under the sample and comparing the ray's height with its first
// coefficient (the spline's value at the cell's corner: nearest sampling). Not exact and not a product
// path: a yardstick for what a plain height-field march costs per fragment and per texel fetch here.
uniform int sv_march_steps;

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    vec3 P0 = vec3(sv_index_scale * ro.xy + sv_index_shift, ro.z);
    vec3 D = vec3(sv_index_scale * rd.xy, rd.z);
    float t, t_end;
    if (!sv_clip_to_box(P0, D, tmin, t, t_end)) return false;
    float dt = (t_end - t) / float(max(sv_march_steps, 1));
    float t_hit = SV_NO_HIT;
    ivec2 last = ivec2(sv_ncells) - ivec2(1);
    bool above = false;  // a hit is a step from above the height to below it (as the exact cast: no walls)
    for (int s = 0; s < sv_march_steps; ++s) {
        float ts = t + (float(s) + 0.5) * dt;
        vec3 p = P0 + ts * D;
        ivec2 c = clamp(ivec2(floor(p.xy)), ivec2(0), last);
        float h = sv_coef_texel(sv_table_address(8 * (c.y * int(sv_ncells.x) + c.x))).x;
        if (p.z > h) above = true;
        else if (above && t_hit == SV_NO_HIT) t_hit = ts;
    }
    if (t_hit == SV_NO_HIT) return false;
    hit.t = t_hit;
    hit.pos = ro + t_hit * rd;
    hit.normal = vec3(0.0, 0.0, 1.0);
    hit.scalar = P0.z + t_hit * D.z + sv_scalar_offset;
    hit.uv = (P0.xy + t_hit * D.xy) / sv_ncells;
    return true;
}
#elif defined(SV_TERRAIN_LEGACY)
// The walk before the rounds below (SV_TERRAIN_LEGACY, kept for the side-by-side timing of
// benchmarks/bench_speedup.py): the cell test inside the walk's loop body. Same hits as the default walk, bit for bit.
bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    // The ray in index space: P(t) = P0 + t D (t unchanged).
    vec3 P0 = vec3(sv_index_scale * ro.xy + sv_index_shift, ro.z);
    vec3 D = vec3(sv_index_scale * rd.xy, rd.z);
    float t, t_end;
    if (!sv_clip_to_box(P0, D, tmin, t, t_end)) return false;

    // Start in the top-level block holding the entry point (with the full hierarchy that is the single
    // root block; a truncated hierarchy, sv_top_level < last level, starts lower: level 0 is a plain
    // cell-by-cell walk, which the benchmarks use to measure what the hierarchy buys).
    int L = sv_top_level;
    ivec2 c = clamp(ivec2(floor((P0.xy + t * D.xy) / float(1 << L))), ivec2(0),
                    ivec2(ceil(sv_ncells / float(1 << L))) - ivec2(1));
    ivec2 stepdir = ivec2(D.x > 0.0 ? 1 : -1, D.y > 0.0 ? 1 : -1);
    float t_hit = SV_NO_HIT;
    ivec2 cell_hit = ivec2(0);
    for (int s = 0; s < sv_max_steps; ++s) {
#ifdef SV_DEBUG_COUNTERS
        sv_count_traversal += 1;
#endif
        float size = float(1 << L);
        vec2 lo = vec2(c) * size;
        vec2 hi = min(lo + vec2(size), sv_ncells);
        vec2 txy = sv_rect_exit(P0, D, lo, hi);
        float tx = txy.x;
        float ty = txy.y;
        float tb = min(min(tx, ty), t_end);
        vec2 mm = sv_block_minmax(L, c);
        float za = P0.z + t * D.z;
        float zb = P0.z + tb * D.z;
        // The ray's heights carry the rounding of P0.z + t D.z (two roundings on terms up to |P0.z| and
        // |t D.z|): widen the overlap test by it, or a crossing at a block's exit is skipped with the block
        // and the next block is entered below the surface (pinholes on plateaus and crater rims).
        float zerr = 2.384185791015625e-07 * (abs(P0.z) + max(abs(t), abs(tb)) * abs(D.z));
        if (max(za, zb) + zerr >= mm.x && min(za, zb) - zerr <= mm.y) {
            if (L > 0) {
                // Descend to the child holding P(t); clamp to c's children (P(t) may sit on a border).
                L -= 1;
                vec2 p = P0.xy + t * D.xy;
                ivec2 child = ivec2(floor(p / float(1 << L)));
                c = clamp(child, 2 * c, 2 * c + ivec2(1));
                continue;
            }
#ifdef SV_DEBUG_TRAVERSAL_ONLY
            // traversal only (debug="traversal"): the first candidate cell is the hit, at the ray's entry
            t_hit = t;
            cell_hit = c;
            break;
#endif
#ifdef SV_DEBUG_COUNTERS
            sv_count_cells += 1;
#endif
            float b0[15];
            float b1[15];
            sv_load_cell(c, b0, b1);
            vec3 o = vec3(P0.xy - vec2(c), P0.z);
            // the cell's segment, widened by the margin (in t) on both ends
            // The margin also covers the rounding of the ray's index coordinates P0 + t D (2 roundings on terms
            // of size |P0.xy| and |t D.xy|, ~u times the grid's size): on a 3600^2 grid seen from afar that
            // exceeds 2^-16 cells, and rays slipped between neighbouring cells and blocks (lines of pinholes).
            float margin = max(SV_CELL_MARGIN, 4.76837158203125e-07 * (max(abs(P0.x), abs(P0.y))
                                                                      + abs(t) * max(abs(D.x), abs(D.y))));
            float dt_margin = margin / max(max(abs(D.x), abs(D.y)), 1e-30);
            float ta_c = t - dt_margin;
            float tb_c = tb + dt_margin;
            // A (nearly) vertical ray crosses no cell edge: margin / |D.xy| is then astronomically large and the
            // segment's start, o + ta d, would lie ~1e25 away (the root's t lost to rounding: a parallel top
            // view drew every pixel at one depth). Its roots lie where the ray is within the cell's height
            // range, so the segment is cut to that slab, padded by its own height and the ray's rounding.
            if (abs(D.z) > 0.0) {
                float zpad = (mm.y - mm.x) + zerr + 1.0e-6 * (abs(mm.x) + abs(mm.y)) + 1.0e-30;
                float tz0 = (mm.x - zpad - P0.z) / D.z;
                float tz1 = (mm.y + zpad - P0.z) / D.z;
                ta_c = max(ta_c, min(tz0, tz1));
                tb_c = min(tb_c, max(tz0, tz1));
            }
            float h0 = sv_triangle_hit(b0, 0, o, D, ta_c, tb_c, margin);
            float h1 = sv_triangle_hit(b1, 1, o, D, ta_c, tb_c, margin);
            float th = min(h0, h1);
            if (th < SV_NO_HIT) {
                t_hit = th;
                cell_hit = c;
                break;
            }
        }
        if (tb >= t_end) break;
        // Step to the neighbouring block across the face the ray leaves through.
        ivec2 parent = c / 2;
        if (tx <= ty) c.x += stepdir.x; else c.y += stepdir.y;
        t = tb;
        ivec2 nb = ivec2(ceil(sv_ncells / size));
        if (c.x < 0 || c.y < 0 || c.x >= nb.x || c.y >= nb.y) break;
        // Entering another parent block: go up, so empty regions are skipped at the coarsest level.
        if (L < sv_top_level && (c / 2) != parent) {
            L += 1;
            c = c / 2;
        }
    }
    if (t_hit == SV_NO_HIT) return false;
    sv_terrain_fill_hit(ro, rd, P0, D, t_hit, cell_hit, hit);
    return true;
}
#else
// The walk in rounds. llvmpipe (the renderer of machines without a GPU) runs the fragments of a SIMD group in
// lock step: every instruction of a branch runs for the whole group, masked, whether or not a fragment takes it;
// only a loop's further iterations are skipped when no fragment of the group needs them (the first always runs).
// A cell test inside the walk's loop body therefore cost every group a full cell test at every walk step. Here
// the walk runs in its own loop until each fragment stands at a candidate cell (or has left the terrain), then
// all test their cells together, with ONE copy of the root finder for both triangles: a round per cell tested
// (per tested cell of the group's slowest fragment), not per walk step. The hits are those of the legacy walk
// above, bit for bit: the cell's hit is min over its triangles of ta + s (s the hit on the rebased segment),
// and the root finder runs on the triangle that may hit first; the other one only when its segment starts before
// that hit (then in a second round for this cell: `retry`).

// Step from block c (level L, exits txy, leaving at tb) to the neighbour the ray enters, going up a level when
// that neighbour has another parent; false when the ray leaves the terrain (or its box) instead.
bool sv_walk_step(vec2 txy, float tb, float t_end, ivec2 stepdir, float size, inout ivec2 c, inout int L,
                  inout float t) {
    if (tb >= t_end) return false;
    ivec2 parent = c / 2;
    if (txy.x <= txy.y) c.x += stepdir.x; else c.y += stepdir.y;
    t = tb;
    ivec2 nb = ivec2(ceil(sv_ncells / size));
    if (c.x < 0 || c.y < 0 || c.x >= nb.x || c.y >= nb.y) return false;
    // Entering another parent block: go up, so empty regions are skipped at the coarsest level.
    if (L < sv_top_level && (c / 2) != parent) {
        L += 1;
        c = c / 2;
    }
    return true;
}

// Triangle `tri` of a cell on the cell-local ray o + t d, t in [ta, tb], rebased to the segment's start as in
// sv_triangle_hit: k, t0, t1, c of sv_graph_patch_prepare (t0, t1 relative to ta).
int sv_triangle_prepare(float b[15], int tri, vec3 o, vec3 d, float ta, float tb, float margin, out float t0,
                        out float t1, out float c[5]) {
    vec3 start = o + ta * d;
    vec3 lo = sv_cell_bary(start.xy, tri);
    vec3 ld = sv_cell_bary(d.xy, tri) - sv_cell_bary(vec2(0.0), tri);
    return sv_graph_patch_prepare(b, lo, ld, start.z, d.z, 0.0, tb - ta, margin, t0, t1, c);
}

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    // The ray in index space: P(t) = P0 + t D (t unchanged).
    vec3 P0 = vec3(sv_index_scale * ro.xy + sv_index_shift, ro.z);
    vec3 D = vec3(sv_index_scale * rd.xy, rd.z);
    float t, t_end;
    if (!sv_clip_to_box(P0, D, tmin, t, t_end)) return false;
    // Start in the top-level block holding the entry point (see the legacy walk above).
    int L = sv_top_level;
    ivec2 c = clamp(ivec2(floor((P0.xy + t * D.xy) / float(1 << L))), ivec2(0),
                    ivec2(ceil(sv_ncells / float(1 << L))) - ivec2(1));
    ivec2 stepdir = ivec2(D.x > 0.0 ? 1 : -1, D.y > 0.0 ? 1 : -1);
    float t_hit = SV_NO_HIT;
    ivec2 cell_hit = ivec2(0);
    int s = 0;
    // the cell under test: its exit tb, bounds mm and the rounding zerr of the ray's heights; in a retry round the
    // triangle whose root is known and the hit so far (rebased)
    float tb = t;
    vec2 mm = vec2(0.0);
    float zerr = 0.0;
    bool retry = false;
    int solved = -1;
    float best = SV_NO_HIT;
    for (int round = 0; round < 2 * sv_max_steps; ++round) {
        if (!retry) {
            // the walk (the legacy loop without its cell test), to the next cell whose bounds the ray meets
            bool cand = false;
            for (; s < sv_max_steps; ++s) {
#ifdef SV_DEBUG_COUNTERS
                sv_count_traversal += 1;
#endif
                float size = float(1 << L);
                vec2 lo = vec2(c) * size;
                vec2 hi = min(lo + vec2(size), sv_ncells);
                vec2 txy = sv_rect_exit(P0, D, lo, hi);
                tb = min(min(txy.x, txy.y), t_end);
                mm = sv_block_minmax(L, c);
                float za = P0.z + t * D.z;
                float zb = P0.z + tb * D.z;
                // the rounding of the ray's heights (legacy walk)
                zerr = 2.384185791015625e-07 * (abs(P0.z) + max(abs(t), abs(tb)) * abs(D.z));
                if (max(za, zb) + zerr >= mm.x && min(za, zb) - zerr <= mm.y) {
                    if (L > 0) {
                        // Descend to the child holding P(t); clamp to c's children (P(t) may sit on a border).
                        L -= 1;
                        vec2 p = P0.xy + t * D.xy;
                        ivec2 child = ivec2(floor(p / float(1 << L)));
                        c = clamp(child, 2 * c, 2 * c + ivec2(1));
                        continue;
                    }
                    cand = true;
                    ++s;
                    break;
                }
                if (!sv_walk_step(txy, tb, t_end, stepdir, size, c, L, t)) {
                    s = sv_max_steps;
                    break;
                }
            }
            if (!cand) break;
#ifdef SV_DEBUG_TRAVERSAL_ONLY
            // traversal only (debug="traversal"): the first candidate cell is the hit, at the ray's entry
            t_hit = t;
            cell_hit = c;
            break;
#endif
#ifdef SV_DEBUG_COUNTERS
            sv_count_cells += 1;
#endif
            solved = -1;
            best = SV_NO_HIT;
        }
#ifndef SV_DEBUG_TRAVERSAL_ONLY
        float b0[15];
        float b1[15];
        sv_load_cell(c, b0, b1);
        vec3 o = vec3(P0.xy - vec2(c), P0.z);
        // the cell's segment, widened by the margin and cut to the slab (as in the legacy walk)
        float margin = max(SV_CELL_MARGIN, 4.76837158203125e-07 * (max(abs(P0.x), abs(P0.y))
                                                                  + abs(t) * max(abs(D.x), abs(D.y))));
        float dt_margin = margin / max(max(abs(D.x), abs(D.y)), 1e-30);
        float ta_c = t - dt_margin;
        float tb_c = tb + dt_margin;
        if (abs(D.z) > 0.0) {
            float zpad = (mm.y - mm.x) + zerr + 1.0e-6 * (abs(mm.x) + abs(mm.y)) + 1.0e-30;
            float tz0 = (mm.x - zpad - P0.z) / D.z;
            float tz1 = (mm.y + zpad - P0.z) / D.z;
            ta_c = max(ta_c, min(tz0, tz1));
            tb_c = min(tb_c, max(tz0, tz1));
        }
        float u0, u1, v0, v1;
        float c0[5];
        float c1[5];
        int k0 = sv_triangle_prepare(b0, 0, o, D, ta_c, tb_c, margin, u0, u1, c0);
        int k1 = sv_triangle_prepare(b1, 1, o, D, ta_c, tb_c, margin, v0, v1, c1);
        if (k0 == SV_PATCH_START) best = min(best, u0);
        if (k1 == SV_PATCH_START) best = min(best, v0);
        // A root found on [t0, t1] is mix(t0, t1, r) >= t0 - (rounding), r in [0, 1]: a triangle whose segment
        // starts after the hit so far by more than that cannot give an earlier hit and is not solved.
        float lb0 = u0 - 4.76837158203125e-07 * (abs(u0) + abs(u1));
        float lb1 = v0 - 4.76837158203125e-07 * (abs(v0) + abs(v1));
        bool open0 = k0 == SV_PATCH_ROOT && solved != 0 && lb0 < best;
        bool open1 = k1 == SV_PATCH_ROOT && solved != 1 && lb1 < best;
#ifndef SV_DEBUG_NO_ROOTS
        if (open0 || open1) {
            // one root finder for both triangles: the one whose segment starts first
            bool first0 = open0 && (!open1 || u0 <= v0);
            float cr[5];
            for (int q = 0; q < 5; ++q) cr[q] = first0 ? c0[q] : c1[q];
            float r0 = first0 ? u0 : v0;
            float r1 = first0 ? u1 : v1;
#ifdef SV_DEBUG_COUNTERS
            sv_count_root_calls += 1;
#endif
            float r = sv_first_root(cr, 4, sv_newton_iterations);
            if (r >= 0.0) best = min(best, mix(r0, r1, r));
            solved = first0 ? 0 : 1;
            bool other = first0 ? (open1 && lb1 < best) : (open0 && lb0 < best);
            if (other) {
                retry = true;
                continue;
            }
        }
#endif
        retry = false;
        if (best < SV_NO_HIT) {
            t_hit = ta_c + best;
            cell_hit = c;
            break;
        }
        // no hit in this cell: step past it (level 0, as at the end of the legacy walk's body)
        vec2 lo = vec2(c);
        vec2 txy = sv_rect_exit(P0, D, lo, min(lo + vec2(1.0), sv_ncells));
        if (!sv_walk_step(txy, tb, t_end, stepdir, 1.0, c, L, t)) break;
#endif
    }
    if (t_hit == SV_NO_HIT) return false;
    sv_terrain_fill_hit(ro, rd, P0, D, t_hit, cell_hit, hit);
    return true;
}
#endif
#ifdef SV_TERRAIN_MESH
#undef sv_surface_hit
#include "lib/terrain/mesh_guided.glsl"
#endif
