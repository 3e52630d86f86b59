// Ray casting the isosurface s = isovalue of a quadratic or cubic spline on the type-6 partition, per
// fragment ([Kalbe2008, sec. 5]).
//
// Proxy: one box per relevant cube (splinevis.volume.program), rasterized with front faces culled, so
// each fragment lies on the cube's far side and the camera may be inside the volume. The fragment tests
// the relevant tetrahedra of its own cube (bit mask, a flat vertex attribute):
// 1. clip the ray by the tetrahedron's barycentric coordinates ([Kalbe2008, sec. 5.3]: lam_i >= 0), with
//    margins against cracks between neighbours (a wide one across the cube's faces, where neighbouring
//    fragments round the ray independently and the splines are C1, and a narrow one inside the cube);
// 2. BB coefficients of s on the tetrahedron: recomputed from the cube's 27 data values with the scheme's
//    averaging rules (encoding "data", the determining data of [Kalbe2008, sec. 5.1] taken to the limit:
//    one value per cube) or read from a table (encoding "coefficients": every coefficient stored);
// 3. restriction to the segment by blossoming ([Kalbe2008, Fig. 10]), isovalue subtracted, first root in
//    [0, 1]: by the stable closed form of the degree (default), bracketed Newton, or the Newton iteration
//    of [Kalbe2008, sec. 5.3] from three starts (selectable; splinevis.volume.root_methods measures them
//    against the robust reference);
// 4. the smallest t over the tetrahedra wins in the cube; across cubes the depth test picks the first.
// Normal: gradient of s from the degree n - 1 coefficients at the hit ([Kalbe2008, sec. 5.3], last
// paragraph).
// The float64 twin is splinevis.volume.raycast.
#include "lib/core/raycast.glsl"
#include "lib/core/table.glsl"
#include "lib/core/roots.glsl"
#include "lib/type6/partition.glsl"
#include "lib/type6/tet_clip.glsl"
#include "lib/simplex/tet_steps.glsl"
#ifdef SV_VOLUME_CUBIC
#include "lib/type6/stencil_cubic.glsl"
#else
#include "lib/type6/stencil_quadratic.glsl"
#endif
#ifdef SV_VOLUME_DETERMINING
// The encoding of [Kalbe2008, sec. 5.1]: per relevant cube only its 56 determining coefficients (sampler
// sv_volume_det, one row of 56 floats per cube); the rest follow from them in the shader.
#include "lib/type6/determining_cubic.glsl"
const int SV_CUBE_VALUES = 56;
#else
const int SV_CUBE_VALUES = 27;
#endif

uniform vec3 sv_inv_spacing;      // index-space direction = sv_inv_spacing * model-space direction
uniform float sv_iso_shifted;     // isovalue - sv_value_ref (the textures hold data - sv_value_ref)
uniform float sv_value_ref;
uniform int sv_newton_iterations;
uniform float sv_cube_margin;     // clip margins in barycentric units: lam_0 (the face on the cube's boundary)
uniform float sv_inner_margin;    // and lam_1..3 (faces inside the cube), see splinevis.volume.program
uniform vec3 sv_padded_dims;      // (nx + 2, ny + 2, nz + 2)
uniform vec3 sv_cube_count;       // (nx, ny, nz): hit.uv = (x, y) / (nx, ny)
#ifdef SV_VOLUME_BLOCKS
uniform int sv_block_size;        // cubes per block edge (proxies are blocks)
const int SV_MAX_BLOCK = 16;      // largest supported block edge (loop bound of the cube walk)
#endif

#ifdef SV_VOLUME_COLOR_FIELD
// A second field on the same grid (the sampler sv_color_data, same layout as sv_volume_data): the
// isosurface is coloured by its spline (same scheme) at the hit; hit.scalar feeds the colormap effect.
float sv_fetch_color(int n) {
    return sv_table_float(sv_color_data, n);
}
#endif

float sv_fetch_linear(int n) {
#if defined(SV_VOLUME_TABLE)
    return sv_table_float(sv_volume_coef, n);
#elif defined(SV_VOLUME_DETERMINING)
    return sv_table_float(sv_volume_det, n);
#else
    return sv_table_float(sv_volume_data, n);
#endif
}

#ifdef SV_VOLUME_TABLE
// Coefficients of tetrahedron t from row `r` of the table (the cube's first row + the tetrahedron's rank).
void sv_load_tet(int t, int r, float f[SV_CUBE_VALUES], out float b[SV_VOL_NCOEF]) {
    int base = r * SV_VOL_NCOEF;
    for (int q = 0; q < SV_VOL_NCOEF; ++q) b[q] = sv_fetch_linear(base + q);
}
#elif defined(SV_VOLUME_DETERMINING)
void sv_load_tet(int t, int r, float f[SV_CUBE_VALUES], out float b[SV_VOL_NCOEF]) {
    sv_tet_coefficients_det(t, f, b);
}
#else
void sv_load_tet(int t, int r, float f[SV_CUBE_VALUES], out float b[SV_VOL_NCOEF]) {
    sv_tet_coefficients(t, f, b);
}
#endif

// The cube's 27 data values (padded volume, x fastest), stencil order of splinevis.volume.schemes.STENCIL;
// field 0 = the volume, field 1 = the colour field.
void sv_load_stencil_of(ivec3 c, int field, out float f[27]) {
    ivec3 dims = ivec3(sv_padded_dims + 0.5);
    int s = 0;
    for (int dz = 0; dz < 3; ++dz) {
        for (int dy = 0; dy < 3; ++dy) {
            int row = ((c.z + dz) * dims.y + (c.y + dy)) * dims.x + c.x;
            for (int dx = 0; dx < 3; ++dx) {
#ifdef SV_VOLUME_COLOR_FIELD
                f[s] = (field == 0) ? sv_fetch_linear(row + dx) : sv_fetch_color(row + dx);
#else
                f[s] = sv_fetch_linear(row + dx);
#endif
                s += 1;
            }
        }
    }
}

// What the shader reads once per cube: the 27 data values (encoding "data"), the cube's determining
// coefficients (row `row` of the determining table), or nothing (the coefficient table is read per tet).
void sv_load_cube(ivec3 c, int row, out float f[SV_CUBE_VALUES]) {
#if defined(SV_VOLUME_TABLE)
    for (int s = 0; s < SV_CUBE_VALUES; ++s) f[s] = 0.0;
#elif defined(SV_VOLUME_DETERMINING)
    for (int k = 0; k < SV_CUBE_VALUES; ++k) f[k] = sv_fetch_linear(row * SV_CUBE_VALUES + k);
#else
    sv_load_stencil_of(c, 0, f);
#endif
}

// First root in [0, 1] of the restricted polynomial minus the isovalue: the stable closed form of the
// degree (default), the Newton iteration of [Kalbe2008, sec. 5.3] from three starts (SV_ROOTS_PAPER), or
// bracketed Newton on convex pieces (SV_ROOTS_BRACKETED); the float64/float32 twins are in
// splinevis.bb.roots.
float sv_first_root_deg(float c[5]) {
#if defined(SV_ROOTS_PAPER)
    return sv_first_root_newton3(c, sv_newton_iterations);
#elif defined(SV_ROOTS_BRACKETED)
    return sv_first_root_bracketed(c, SV_VOL_DEGREE, sv_newton_iterations);
#elif defined(SV_VOLUME_CUBIC)
    return sv_first_root_cubic(c);
#else
    return sv_first_root_quadratic(c);
#endif
}

void sv_restrict(float b[SV_VOL_NCOEF], vec4 l0, vec4 l1, out float c[5]) {
#ifdef SV_VOLUME_CUBIC
    sv_restrict_tet3(b, l0, l1, c);
#else
    sv_restrict_tet2(b, l0, l1, c);
#endif
}

// Gradient in cube-local coordinates of tetrahedron t's polynomial at barycentric point l, and its value.
vec3 sv_tet_gradient(float b[SV_VOL_NCOEF], int t, vec4 l, out float value) {
    float a[4];
#ifdef SV_VOLUME_CUBIC
    float a2[10];
    sv_tet_step3(b, l, a2);
    sv_tet_step2(a2, l, a);
#else
    sv_tet_step2(b, l, a);
#endif
    value = sv_tet_step1(a, l);
    vec3 g = vec3(0.0);
    for (int i = 0; i < 4; ++i) g += a[i] * SV_TET_BARY[4 * t + i].xyz;
    return float(SV_VOL_DEGREE) * g;
}

#ifdef SV_OUT_CURVATURE
// Mean and Gaussian curvature of the level set at barycentric point l of tetrahedron t, from the gradient g
// and Hessian H (model coordinates): H from the degree-2 blossom a2 of the polynomial at l,
// H = n (n - 1) G^T A G with A_ij = a2[e_i + e_j] and G_i = grad lam_i, scaled by 1 / spacing per axis.
// mean = (|g|^2 tr H - g^T H g) / (2 |g|^3), gauss = g^T adj(H) g / |g|^4 ([Goldman2005]):
// 1/r and 1/r^2 for a sphere of radius r of a field increasing outwards. Twin: VolumeSpline.curvature.
vec2 sv_tet_curvature(float b[SV_VOL_NCOEF], int t, vec4 l, vec3 g) {
    float a2[10];
#ifdef SV_VOLUME_CUBIC
    sv_tet_step3(b, l, a2);
#else
    for (int q = 0; q < 10; ++q) a2[q] = b[q];
#endif
    // multi_indices(2, 3) order: 2000 1100 1010 1001 0200 0110 0101 0020 0011 0002
    mat4 A = mat4(a2[0], a2[1], a2[2], a2[3],
                  a2[1], a2[4], a2[5], a2[6],
                  a2[2], a2[5], a2[7], a2[8],
                  a2[3], a2[6], a2[8], a2[9]);
    mat4x3 G;  // column i = grad lam_i (model coordinates)
    for (int i = 0; i < 4; ++i) G[i] = SV_TET_BARY[4 * t + i].xyz * sv_inv_spacing;
    mat3 H = float(SV_VOL_DEGREE * (SV_VOL_DEGREE - 1)) * (G * A * transpose(G));
    float gg = dot(g, g);
    float mean = (gg * (H[0][0] + H[1][1] + H[2][2]) - dot(g, H * g)) / (2.0 * gg * sqrt(gg));
    mat3 adj = transpose(mat3(cross(H[1], H[2]), cross(H[2], H[0]), cross(H[0], H[1])));
    float gauss = dot(g, adj * g) / (gg * gg);
    return vec2(mean, gauss);
}
#endif

// First hit (smallest t >= tmin) inside cube c along the cube-local ray P0 + t D over the cube's relevant
// tetrahedra (mask); returns SV_NO_HIT if none, else t with the tetrahedron and its rank in the table.
float sv_cube_first_hit(ivec3 c, int mask, int row, vec3 P0, vec3 D, float tmin, float f[SV_CUBE_VALUES],
                        out int tet_best, out int rank_best) {
    float t_best = SV_NO_HIT;
    tet_best = -1;
    rank_best = 0;
    int r = 0;   // rank of t among the cube's relevant tetrahedra (row in the coefficient table)
    for (int t = 0; t < 24; ++t) {
        if (((mask >> t) & 1) == 0) continue;
        int rank = r;
        r += 1;
        vec4 lo;
        vec4 ld;
        for (int i = 0; i < 4; ++i) {
            vec4 m = SV_TET_BARY[4 * t + i];
            lo[i] = dot(m.xyz, P0) + m.w;
            ld[i] = dot(m.xyz, D);
        }
        float ta = tmin;
        float tb = 3.0e38;
        bool empty = false;
        for (int i = 0; i < 4; ++i) {
            float lim = -(i == 0 ? sv_cube_margin : sv_inner_margin) - lo[i];
            if (ld[i] > 0.0) ta = max(ta, lim / ld[i]);
            else if (ld[i] < 0.0) tb = min(tb, lim / ld[i]);
            else if (lim > 0.0) empty = true;
        }
        if (empty || !(ta <= tb) || ta >= t_best) continue;
        float b[SV_VOL_NCOEF];
        sv_load_tet(t, row + rank, f, b);
        float cc[5];
        sv_restrict(b, lo + ta * ld, lo + tb * ld, cc);
        for (int k = 0; k <= SV_VOL_DEGREE; ++k) cc[k] -= sv_iso_shifted;
        float s = sv_first_root_deg(cc);
        if (s < 0.0) continue;
        float th = ta + s * (tb - ta);
        if (th < t_best) {
            t_best = th;
            tet_best = t;
            rank_best = rank;
        }
    }
    return t_best;
}

#ifndef SV_VOLUME_LEGACY
// Rank of tetrahedron t among the cube's relevant ones (mask bits below t), without GLSL 4's bitCount.
int sv_bits_below(int mask, int t) {
    int x = mask & ((1 << t) - 1);
    x = x - ((x >> 1) & 0x55555555);
    x = (x & 0x33333333) + ((x >> 2) & 0x33333333);
    x = (x + (x >> 4)) & 0x0F0F0F0F;
    return (x * 0x01010101) >> 24;
}

// sv_cube_first_hit with the same result, bit for bit, at a cost per tetrahedron the ray crosses. llvmpipe runs
// a loop body for the whole SIMD group, masked, as often as its slowest fragment needs: the 24 iterations of
// the loop above cost 24 full tetrahedron tests each (clip, coefficients, restriction, root). Here the cheap
// clip of all 24 finds the candidates (relevant, segment not empty), and the loop runs once per candidate, in
// increasing t as above (ties in t keep the lowest tetrahedron, as above).
float sv_cube_first_hit_candidates(ivec3 c, int mask, int row, vec3 P0, vec3 D, float tmin, float f[SV_CUBE_VALUES],
                                   out int tet_best, out int rank_best) {
    float t_best = SV_NO_HIT;
    tet_best = -1;
    rank_best = 0;
    int cand = sv_tet_clip_all(P0, D, tmin, sv_cube_margin, sv_inner_margin, mask);
    for (int k = 0; k < 24; ++k) {
        if (cand == 0) break;
        int low = cand & (-cand);
        cand ^= low;
        int t = int(log2(float(low)) + 0.5);  // low = 2^t exactly (t < 24)
        vec4 lo;
        vec4 ld;
        for (int i = 0; i < 4; ++i) {
            vec4 m = SV_TET_BARY[4 * t + i];
            lo[i] = dot(m.xyz, P0) + m.w;
            ld[i] = dot(m.xyz, D);
        }
        float ta = tmin;
        float tb = 3.0e38;
        for (int i = 0; i < 4; ++i) {
            float lim = -(i == 0 ? sv_cube_margin : sv_inner_margin) - lo[i];
            if (ld[i] > 0.0) ta = max(ta, lim / ld[i]);
            else if (ld[i] < 0.0) tb = min(tb, lim / ld[i]);
        }
        if (ta >= t_best) continue;
        int rank = sv_bits_below(mask, t);
        float b[SV_VOL_NCOEF];
        sv_load_tet(t, row + rank, f, b);
        float cc[5];
        sv_restrict(b, lo + ta * ld, lo + tb * ld, cc);
        for (int q = 0; q <= SV_VOL_DEGREE; ++q) cc[q] -= sv_iso_shifted;
        float s = sv_first_root_deg(cc);
        if (s < 0.0) continue;
        float th = ta + s * (tb - ta);
        if (th < t_best) {
            t_best = th;
            tet_best = t;
            rank_best = rank;
        }
    }
    return t_best;
}
#endif

#ifdef SV_VOLUME_BLOCKS
// Per-cube masks and table rows of the drawn blocks (sampler sv_volume_mask, one texel per cube, block after
// block, x fastest inside a block): .r = mask (24 bits, exact in float32), .g/.b = first table row as
// 12-bit halves. `a` is the cube within block `block`.
vec4 sv_cube_info(int block, ivec3 a) {
    int k = (block * sv_block_size + a.z) * sv_block_size * sv_block_size + a.y * sv_block_size + a.x;
    return sv_table_texel(sv_volume_mask, k);
}
#endif

#if defined(SV_VOLUME_BLOCKS) && !defined(SV_VOLUME_LEGACY)
// One DDA step from cube a of the block (exits texit, leaving at tb) to the cube the ray enters; false when it
// leaves the block (or its segment [t0, t1]).
bool sv_block_step(vec3 texit, float tb, float t1, ivec3 stepdir, ivec3 iext, inout ivec3 a) {
    if (tb >= t1) return false;
    if (texit.x <= texit.y && texit.x <= texit.z) a.x += stepdir.x;
    else if (texit.y <= texit.z) a.y += stepdir.y;
    else a.z += stepdir.z;
    return !(any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, iext)));
}
#endif

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    vec3 D = sv_inv_spacing * rd;   // index units per unit of t (t is the model-space parameter of ro + t rd)
    float f[SV_CUBE_VALUES];
    float t_best = SV_NO_HIT;
    int tet_best = -1;
    int rank_best = 0;
    int row = 0;
    ivec3 c;
    vec3 P0;
#ifdef SV_VOLUME_BLOCKS
    // Proxy = a block of cubes: walk its cubes front to back (3-D DDA) and stop at the first hit. The
    // fragment's block-local position (exact at the block's corners) locates the ray; cube a of the block
    // spans [a, a + 1] in these coordinates.
    ivec3 b0 = ivec3(sv_cubeVSOut.xyz + 0.5);                 // first cube of the block
    int block = int(sv_cubeVSOut.w);                          // exact integer (no rounding: see below)
    vec3 ext = min(vec3(sv_block_size), sv_cube_count - vec3(b0));
    vec3 Pb = sv_localVSOut;
    float t0 = tmin;
    float t1 = 3.0e38;
    for (int k = 0; k < 3; ++k) {
        if (abs(D[k]) < 1e-30) continue;
        float ta = (0.0 - Pb[k]) / D[k];
        float tb = (ext[k] - Pb[k]) / D[k];
        t0 = max(t0, min(ta, tb));
        t1 = min(t1, max(ta, tb));
    }
    if (!(t0 <= t1)) return false;
    ivec3 iext = ivec3(ext + 0.5);
    // start in the cube holding the entry point, nudged inside along the ray
    ivec3 a = clamp(ivec3(floor(Pb + (t0 + 1e-4 * (t1 - t0)) * D)), ivec3(0), iext - ivec3(1));
    ivec3 stepdir = ivec3(D.x > 0.0 ? 1 : -1, D.y > 0.0 ? 1 : -1, D.z > 0.0 ? 1 : -1);
#ifdef SV_VOLUME_LEGACY
    // the walk before the rounds below (kept for the side-by-side timing of benchmarks/bench_speedup.py): the cube
    // test inside the DDA's loop body; the same hits, bit for bit
    for (int s = 0; s < 3 * SV_MAX_BLOCK; ++s) {
        vec3 lo = vec3(a);
        vec3 texit;
        for (int k = 0; k < 3; ++k) {
            texit[k] = abs(D[k]) < 1e-30 ? 3.0e38 : ((D[k] > 0.0 ? lo[k] + 1.0 : lo[k]) - Pb[k]) / D[k];
        }
        float tb = min(min(texit.x, texit.y), texit.z);
        ivec3 cc = b0 + a;
        vec4 info = sv_cube_info(block, a);
        // info holds exact integers; no "+ 0.5" rounding: above 2^23 float32 cannot hold x + 0.5 and
        // rounds it to the even neighbour, which flips the low bits of a mask with bit 23 set
        int mask = int(info.r);
        if (mask != 0) {
            int crow = 4096 * int(info.g) + int(info.b);
            vec3 Pc = Pb - vec3(a);
            sv_load_cube(cc, crow, f);
            int tb_tet;
            int tb_rank;
            // tetrahedra are clipped by their own (margin-widened) barycentric extent, not by the block's
            // segment, so a root on a block face is found by the cubes on both sides (no crack)
            float th = sv_cube_first_hit(cc, mask, crow, Pc, D, tmin, f, tb_tet, tb_rank);
            if (th < SV_NO_HIT) {
                t_best = th;
                tet_best = tb_tet;
                rank_best = tb_rank;
                row = crow;
                c = cc;
                P0 = Pc;
                break;
            }
        }
        if (tb >= t1) break;
        if (texit.x <= texit.y && texit.x <= texit.z) a.x += stepdir.x;
        else if (texit.y <= texit.z) a.y += stepdir.y;
        else a.z += stepdir.z;
        if (any(lessThan(a, ivec3(0))) || any(greaterThanEqual(a, iext))) break;
    }
#else
    // Rounds (as the terrain's walk, glsl/programs/terrain.glsl): the DDA runs in its own loop to the next cube
    // holding relevant tetrahedra, then that cube is tested; a cube test per round, not per cube crossed.
    int steps = 0;
    for (int round = 0; round < 3 * SV_MAX_BLOCK; ++round) {
        bool found = false;
        vec3 texit = vec3(0.0);
        float tb = 0.0;
        vec4 info = vec4(0.0);
        for (; steps < 3 * SV_MAX_BLOCK; ++steps) {
            vec3 lo = vec3(a);
            for (int k = 0; k < 3; ++k) {
                texit[k] = abs(D[k]) < 1e-30 ? 3.0e38 : ((D[k] > 0.0 ? lo[k] + 1.0 : lo[k]) - Pb[k]) / D[k];
            }
            tb = min(min(texit.x, texit.y), texit.z);
            info = sv_cube_info(block, a);
            if (int(info.r) != 0) {
                found = true;
                ++steps;
                break;
            }
            if (!sv_block_step(texit, tb, t1, stepdir, iext, a)) {
                steps = 3 * SV_MAX_BLOCK;
                break;
            }
        }
        if (!found) break;
        ivec3 cc = b0 + a;
        int mask = int(info.r);
        int crow = 4096 * int(info.g) + int(info.b);
        vec3 Pc = Pb - vec3(a);
        sv_load_cube(cc, crow, f);
        int tb_tet;
        int tb_rank;
        float th = sv_cube_first_hit_candidates(cc, mask, crow, Pc, D, tmin, f, tb_tet, tb_rank);
        if (th < SV_NO_HIT) {
            t_best = th;
            tet_best = tb_tet;
            rank_best = tb_rank;
            row = crow;
            c = cc;
            P0 = Pc;
            break;
        }
        if (!sv_block_step(texit, tb, t1, stepdir, iext, a)) break;
    }
#endif
    if (tet_best < 0) return false;
#else
    c = ivec3(sv_cubeVSOut.xyz + 0.5);
    int mask = int(sv_cubeVSOut.w + 0.5) + 4096 * int(sv_cube_extraVSOut.x + 0.5);
    row = 4096 * int(sv_cube_extraVSOut.y + 0.5) + int(sv_cube_extraVSOut.z + 0.5);
    // The ray in cube-local coordinates: the interpolated local position of this fragment (exact at the
    // proxy's corners).
    P0 = sv_localVSOut;
    sv_load_cube(c, row, f);
#ifdef SV_VOLUME_LEGACY
    t_best = sv_cube_first_hit(c, mask, row, P0, D, tmin, f, tet_best, rank_best);
#else
    t_best = sv_cube_first_hit_candidates(c, mask, row, P0, D, tmin, f, tet_best, rank_best);
#endif
    if (tet_best < 0) return false;
#endif

    float b[SV_VOL_NCOEF];
    sv_load_tet(tet_best, row + rank_best, f, b);
    vec3 P = P0 + t_best * D;
    vec4 l;
    for (int i = 0; i < 4; ++i) {
        vec4 m = SV_TET_BARY[4 * tet_best + i];
        l[i] = dot(m.xyz, P) + m.w;
    }
    float value;
    vec3 g = sv_tet_gradient(b, tet_best, l, value);
    hit.t = t_best;
    hit.pos = ro + t_best * rd;
    hit.normal = g * sv_inv_spacing;   // chain rule: d/dx_model = d/dx_local * (1 / spacing)
    hit.scalar = value + sv_value_ref;
#ifdef SV_VOLUME_COLOR_FIELD
    float f2[27];
    float b2[SV_VOL_NCOEF];
    sv_load_stencil_of(c, 1, f2);
    sv_tet_coefficients(tet_best, f2, b2);
    float value2;
    vec3 g2 = sv_tet_gradient(b2, tet_best, l, value2);
    hit.scalar = value2;
#endif
#ifdef SV_OUT_CURVATURE
    hit.curvature = sv_tet_curvature(b, tet_best, l, hit.normal);
#endif
    hit.uv = (vec2(c.xy) + P.xy) / sv_cube_count.xy;
    return true;
}
