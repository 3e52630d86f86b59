// Mesh-guided exact ray casting of a terrain spline (program option proxy="mesh"; the derivations are in
// splinevis/terrain/mesh_proxy.py, the float64 twin of the tracing is splinevis.terrain.trace). Included by
// programs/terrain.glsl after the full hierarchy walk, which is then named sv_surface_hit_full.
//
// The proxy is a lifted tessellation of the spline (above the surface everywhere, by a proven bound) closed by
// side walls and a bottom: the region R under it holds the surface. With the eye outside R (decided per frame
// on the CPU), back faces are culled and a front-facing fragment starts its ray at its own point (t = 0; ro is
// the fragment): the surface is not crossed before it. From there the ray's height above the surface,
// g(t) = z(t) - s(x(t), y(t)), is traced to its first zero by steps that cannot pass it: with |g''| <= K on
// the piece (K from the second differences of its coefficients along the ray's direction), sigma g(t + h) >= sigma (g + g' h) - K h^2 / 2 > 0 (sigma the sign of g at the
// start) for h below the positive root of that quadratic, which is the step taken. Steps stop at the piece's
// edges (where the next piece's derivative and bound apply); they converge quadratically to a simple root. A
// ray above the surface that rises above the lifted mesh (g > G) has left R: it is a miss here, and a later
// front face of R along the same ray (a fragment of its own) finds a hit behind. Blocks of the min/max
// hierarchy that the ray passes wholly on its side are skipped. While the eye may be inside R, the actor
// compiles SV_TERRAIN_MESH_INSIDE instead: front faces culled, back faces run the full walk from the eye.
#include "lib/simplex/quartic_unrolled.glsl"
uniform int sv_mesh_steps;
uniform int sv_mesh_skip_level;

// The 15 coefficients of piece tri of cell c, the bound M of the Hessian's spectral norm on the cell (index
// units) and the bound G of the lifted mesh's height above the spline on the cell, which the mesh proxy's
// coefficient table keeps in the cell's two spare floats (splinevis.terrain.mesh_proxy.trace_bounds).
// Constant indices only (no scratch arrays on llvmpipe).
void sv_load_piece(ivec2 c, int tri, out float b[15], out float M, out float G) {
    ivec2 first = sv_table_address(8 * (c.y * int(sv_ncells.x) + c.x));
    vec4 t0 = sv_coef_texel(first);
    vec4 t1 = sv_coef_texel(first + ivec2(1, 0));
    vec4 t2 = sv_coef_texel(first + ivec2(2, 0));
    vec4 t3 = sv_coef_texel(first + ivec2(3, 0));
    vec4 t4 = sv_coef_texel(first + ivec2(4, 0));
    vec4 t5 = sv_coef_texel(first + ivec2(5, 0));
    vec4 t6 = sv_coef_texel(first + ivec2(6, 0));
    vec4 t7 = sv_coef_texel(first + ivec2(7, 0));
    bool one = tri == 1;
    b[0] = one ? t3.w : t0.x;  b[1] = one ? t4.x : t0.y;  b[2] = one ? t4.y : t0.z;  b[3] = one ? t4.z : t0.w;
    b[4] = one ? t4.w : t1.x;  b[5] = one ? t5.x : t1.y;  b[6] = one ? t5.y : t1.z;  b[7] = one ? t5.z : t1.w;
    b[8] = one ? t5.w : t2.x;  b[9] = one ? t6.x : t2.y;  b[10] = one ? t6.y : t2.z; b[11] = one ? t6.z : t2.w;
    b[12] = one ? t6.w : t3.x; b[13] = one ? t7.x : t3.y; b[14] = one ? t7.y : t3.z;
    M = t7.z;
    G = t7.w;
}

#ifdef SV_TERRAIN_MESH_INSIDE
bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    if (gl_FrontFacing) return false;
    return sv_surface_hit_full(ro, rd, tmin, hit);
}
#else
bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    if (!gl_FrontFacing) return false;
    vec3 P0 = vec3(sv_index_scale * ro.xy + sv_index_shift, ro.z);
    vec3 D = vec3(sv_index_scale * rd.xy, rd.z);
    ivec2 last = ivec2(sv_ncells) - ivec2(1);
    float t_end, t_box;
    if (!sv_clip_to_box(P0, D, 0.0, t_box, t_end)) return false;
    float dmax = max(abs(D.x), abs(D.y));
    float skip = float(1 << sv_mesh_skip_level);
    ivec2 nblocks = ivec2(ceil(sv_ncells / skip)) - ivec2(1);
    float t = 0.0;
    float sigma = 0.0;  // the side of the surface the ray starts on (+1 above, -1 below), set by the first step
    float f;
    vec3 a;
    vec3 du, dv;
    bool found = false;
    bool missed = false;  // left R or the terrain's box: no hit from this fragment
    float t_lo = 0.0;  // the last point known not past the first root
    bool inside = false;  // the ray has been seen under the lifted mesh
    bool top = sv_mesh_cellVSOut.x >= 0.0;  // a fragment of the top mesh (walls and bottom carry -1)
    int backs = 0;
    for (int s = 0; s < sv_mesh_steps; ++s) {
        vec3 P = P0 + t * D;
        // the piece the ray is in or entering: the point nudged along the ray by more than its rounding (the
        // full walk's cell margin), so a ray on a border (after a step to it, or running along a cell edge or a
        // diagonal) reads the piece and the block ahead, whose borders lie ahead of it
        float mg = max(SV_CELL_MARGIN, 4.76837158203125e-07 * (max(abs(P0.x), abs(P0.y)) + abs(t) * dmax));
        vec2 ahead = P.xy + mg * sign(D.xy);
        // a block of the hierarchy (level sv_mesh_skip_level) that the ray passes wholly on its side: skip it
        ivec2 bk = clamp(ivec2(floor(ahead / skip)), ivec2(0), nblocks);
        vec2 blo = vec2(bk) * skip;
        vec2 bhi = min(blo + vec2(skip), sv_ncells);
        vec2 bxy = sv_rect_exit(P0, D, blo, bhi);
        float tbk = min(min(bxy.x, bxy.y), t_end);
        vec2 mm = sv_block_minmax(sv_mesh_skip_level, bk);
        float za = P.z;
        float zb = P0.z + tbk * D.z;
        float zerr = 2.384185791015625e-07 * (abs(P0.z) + max(abs(t), abs(tbk)) * abs(D.z));
        bool clear = sigma > 0.0 ? min(za, zb) - zerr > mm.y : (sigma < 0.0 && max(za, zb) + zerr < mm.x);
        ivec2 c = clamp(ivec2(floor(ahead)), ivec2(0), last);
        vec2 local = P.xy - vec2(c);
        int tri = local.y - local.x + mg * sign(D.y - D.x) > 0.0 ? 1 : 0;
        float b[15];
        float M, G;
        sv_load_piece(c, tri, b, M, G);
        sv_tri_quartic_fa(b, sv_cell_bary(local, tri), f, a);
        // barycentric directions of u and v on T0 = (1 - u, u - v, v) and T1 = (1 - v, u, v - u)
        du = tri == 0 ? vec3(-1.0, 1.0, 0.0) : vec3(0.0, 1.0, -1.0);
        dv = tri == 0 ? vec3(0.0, -1.0, 1.0) : vec3(-1.0, 0.0, 1.0);
        float g = P.z - f;
        float gp = D.z - 4.0 * (dot(du, a) * D.x + dot(dv, a) * D.y);
        // rounding of g: the ray's height (two roundings on |P0.z| and |t D.z|) and the evaluation (a few ulps
        // of the coefficients' size)
        float gerr = 2.384185791015625e-07 * (abs(P0.z) + abs(t * D.z) + 4.0 * abs(f) + 4.0 * abs(b[0]));
        if (abs(g) <= gerr) {
            found = true;
            break;
        }
        // a fragment of the top mesh that lies under the surface: the rasterizer extrapolated it past its
        // triangle's edge (on a steep piece by more than the lift); the ray met the surface just before it, so it
        // backs up (twice the linear estimate of the distance, up to 3 times) and starts from above
        if (sigma == 0.0 && top && g < -gerr && gp < 0.0 && backs < 3) {
            t -= 2.0 * g / gp;
            t_lo = t;
            backs += 1;
            continue;
        }
        if (sigma == 0.0) sigma = g > 0.0 ? 1.0 : -1.0;
        if (sigma * g < 0.0) {
            // the sign flipped at a border (the next piece's value there differs by rounding): a Newton step
            t = clamp(t - g / (abs(gp) < 1e-30 ? -sigma * 1e-30 : gp), t_lo, t);
            found = true;
            break;
        }
        // above the lifted mesh after having been under it: out of R. (A fragment's own point may lie above the
        // mesh: the rasterizer snaps vertices to subpixels and extrapolates attributes past a triangle's edges,
        // on a cliff by far more than the lift. Such a ray enters R a little later, through this fragment's face.)
        if (g <= G + gerr) inside = true;
        else if (sigma > 0.0 && inside) {
            missed = true;
            break;
        }
        // the step: the positive root of sigma g + sigma gp h - K h^2 / 2, in the form without cancellation
        float sg = sigma * g;
        float sgp = sigma * gp;
        float K = sv_tri_quartic_d2_bound(b, D.x * du + D.y * dv);
        float h = 2.0 * sg / max(sqrt(max(sgp * sgp + 2.0 * K * sg, 0.0)) - sgp, 1e-30);
        // no further than the piece's border (the cell's edges and its diagonal u = v)
        vec2 cl = vec2(c);
        vec2 cxy = sv_rect_exit(P0, D, cl, cl + vec2(1.0));
        float dw = D.y - D.x;
        float tdg = abs(dw) < 1e-30 ? 3.0e38 : ((P0.x - cl.x) - (P0.y - cl.y)) / dw;
        float tb = min(cxy.x, cxy.y);
        if (tdg > t) tb = min(tb, tdg);
        if (clear) tb = max(tb, tbk);
        bool cross = clear || t + h >= tb;
        t = cross ? tb : t + h;
        t_lo = t;
        vec2 q = P0.xy + t * D.xy;
        // the ray leaves the terrain's box, or the domain (R lies over it: the ray does not come back)
        if (t >= t_end || q.x < 0.0 || q.y < 0.0 || q.x > sv_ncells.x || q.y > sv_ncells.y) {
            missed = true;
            break;
        }
    }
    if (missed) return false;
    // not converged in sv_mesh_steps steps (a ray crawling past a near-double root, a grazing silhouette): the full
    // walk from the fragment
    if (!found) return sv_surface_hit_full(ro, rd, 0.0, hit);
#ifdef SV_OUT_CURVATURE
    vec3 Ph = P0 + t * D;
    sv_terrain_fill_hit(ro, rd, P0, D, t, clamp(ivec2(floor(Ph.xy)), ivec2(0), last), hit);
#else
    vec3 Ph = P0 + t * D;
    hit.t = t;
    hit.pos = ro + t * rd;
    hit.normal = vec3(-4.0 * dot(du, a) * sv_index_scale.x, -4.0 * dot(dv, a) * sv_index_scale.y, 1.0);
    hit.scalar = f + sv_scalar_offset;
    hit.uv = Ph.xy / sv_ncells;
#endif
    return true;
}
#endif
