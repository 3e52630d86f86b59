// Mesh-guided exact ray casting of a terrain spline (program option proxy="mesh"; the derivation of the lifted
// mesh and what works is in splinevis/terrain/mesh_proxy.py). Included by programs/terrain.glsl after the full
// hierarchy walk, which is then named sv_surface_hit_full.
//
// The proxy is a lifted tessellation of the spline (above the surface everywhere, by a proven bound) closed by
// side walls and a bottom; the actor culls per frame the faces this file discards. With the eye outside the
// region under it (uniform sv_mesh_eye_inside = 0, decided per frame on the CPU), a front-facing fragment starts the ray at its own
// point (t = 0; ro is the fragment): the surface is not crossed before it. The cells along the ray are tested
// from the fragment's cell (the flat vertex attribute sv_mesh_cell; walls and bottom carry -1 and locate it),
// sv_mesh_cells cells at most, each bracketed by its prism (level-0 min/max) and tested exactly as the full
// walk does; then the full walk continues from where this stopped. Back faces are discarded. With the eye
// (possibly) inside, front faces are discarded and back faces run the full walk from the eye, as the box does.
uniform int sv_mesh_cells;
uniform int sv_mesh_eye_inside;

// Normal, scalar, uv and curvature of a hit at t_hit in cell cell_hit (as the full walk fills them).
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
    sv_tri_quartic_jet(b, l, f, a, dd);
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

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    if (sv_mesh_eye_inside == 1 && sv_parallel == 0) {
        if (gl_FrontFacing) return false;
        return sv_surface_hit_full(ro, rd, tmin, hit);
    }
    if (!gl_FrontFacing) return false;
    vec3 P0 = vec3(sv_index_scale * ro.xy + sv_index_shift, ro.z);
    vec3 D = vec3(sv_index_scale * rd.xy, rd.z);
    ivec2 last = ivec2(sv_ncells) - ivec2(1);
    ivec2 c = sv_mesh_cellVSOut.x >= 0.0 ? ivec2(sv_mesh_cellVSOut + vec2(0.5))
                                         : clamp(ivec2(floor(P0.xy)), ivec2(0), last);
    ivec2 stepdir = ivec2(D.x > 0.0 ? 1 : -1, D.y > 0.0 ? 1 : -1);
    float t = 0.0;
    // where the ray leaves the terrain's box (as the full walk clips it): no hit beyond, and a finite end for
    // a vertical ray, whose cell segment is otherwise unbounded (its rounding estimates then are too)
    float t_end = 3.0e38;
    vec3 blo = vec3(0.0, 0.0, sv_zrange.x);
    vec3 bhi = vec3(sv_ncells, sv_zrange.y);
    for (int k = 0; k < 3; ++k) {
        if (abs(D[k]) >= 1e-30) t_end = min(t_end, max((blo[k] - P0[k]) / D[k], (bhi[k] - P0[k]) / D[k]));
    }
    for (int s = 0; s < sv_mesh_cells; ++s) {
        vec2 lo = vec2(c);
        vec2 hi = lo + vec2(1.0);
        float tx = abs(D.x) < 1e-30 ? 3.0e38 : ((D.x > 0.0 ? hi.x : lo.x) - P0.x) / D.x;
        float ty = abs(D.y) < 1e-30 ? 3.0e38 : ((D.y > 0.0 ? hi.y : lo.y) - P0.y) / D.y;
        float tb = min(min(tx, ty), t_end);
        vec2 mm = sv_block_minmax(0, c);
        float za = P0.z + t * D.z;
        float zb = P0.z + tb * D.z;
        float zerr = 2.384185791015625e-07 * (abs(P0.z) + max(abs(t), abs(tb)) * abs(D.z));
        if (max(za, zb) + zerr >= mm.x && min(za, zb) - zerr <= mm.y) {
            float b0[15];
            float b1[15];
            sv_load_cell(c, b0, b1);
            vec3 o = vec3(P0.xy - vec2(c), P0.z);
            float margin = max(SV_CELL_MARGIN, 4.76837158203125e-07 * (max(abs(P0.x), abs(P0.y))
                                                                      + abs(t) * max(abs(D.x), abs(D.y))));
            float dt_margin = margin / max(max(abs(D.x), abs(D.y)), 1e-30);
            float ta_c = t - dt_margin;
            float tb_c = tb + dt_margin;
            if (abs(D.z) > 0.0) {  // (nearly) vertical rays: cut to the cell's slab (as the full walk)
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
                sv_terrain_fill_hit(ro, rd, P0, D, th, c, hit);
                return true;
            }
        }
        if (tb >= t_end) return false;  // the ray leaves the terrain's box (a vertical ray: its cell's column)
        if (tx <= ty) c.x += stepdir.x; else c.y += stepdir.y;
        t = tb;
        // R lies over the domain (a rectangle): a ray leaving it does not come back
        if (c.x < 0 || c.y < 0 || c.x > last.x || c.y > last.y) return false;
    }
    return sv_surface_hit_full(ro, rd, t, hit);
}
