// Ray casting one quartic BB triangle patch z = f(x, y) (the foundation's analytic test surface and the
// per-patch core of the terrain program; [Reis2008, sec. V-VI]).
//
// Steps 1-3 are lib/simplex/graph_patch.glsl (shared with every terrain triangle):
// 1. Clip the ray against the prism over the triangle between the smallest and largest coefficient
//    (the convex-hull property bounds f there).
// 2. Restrict f to the projected segment by blossoming ([Reis2008, eqs. (6)-(7)]): five univariate BB
//    coefficients; subtract the ray's height, itself degree-elevated to a quartic.
// 3. First root in [0,1] (lib/core/roots.glsl sv_first_root): bracketed Newton on convex pieces, or the
//    Newton iteration from secure starting points of [Reis2008, sec. V] when SV_ROOTS_PAPER is defined.
// 4. Value, gradient (and Hessian for curvature) by de Casteljau at the hit (lib/simplex/bb_triangle.glsl).
#include "lib/core/raycast.glsl"
#include "lib/core/table.glsl"
#include "lib/simplex/bb_triangle.glsl"
#include "lib/simplex/graph_patch.glsl"

#ifdef SV_PATCH_TEXTURE
// Coefficients from a table (lib/core/table.glsl; VTK declares the sampler sv_patch_coeffs): patch id p's 15
// coefficients (+1 padding) are texels 4 p .. 4 p + 3. The patch id is a flat vertex attribute of the proxy.
// This is the path terrains and volumes use for millions of patches; here it proves the plumbing.
void sv_patch_load(out float b[15]) {
    int row = int(sv_patch_idVSOut + 0.5);
    for (int q = 0; q < 4; ++q) {
        vec4 v = sv_table_texel(sv_patch_coeffs, 4 * row + q);
        for (int r = 0; r < 4; ++r) {
            if (4 * q + r < 15) b[4 * q + r] = v[r];
        }
    }
}
#else
uniform float sv_patch_b[15];       // BB coefficients (heights), multi_indices(4, 2) order
void sv_patch_load(out float b[15]) {
    for (int q = 0; q < 15; ++q) b[q] = sv_patch_b[q];
}
#endif
uniform vec3 sv_patch_bary0;        // rows of the matrix M with lam = M * (x, y, 1)
uniform vec3 sv_patch_bary1;
uniform vec3 sv_patch_bary2;
uniform int sv_newton_iterations;

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    float b[15];
    sv_patch_load(b);
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    // Barycentric coordinates along the ray are affine in t: lam(t) = lam_o + t * lam_d.
    mat3 m = transpose(mat3(sv_patch_bary0, sv_patch_bary1, sv_patch_bary2));  // rows -> GLSL matrix
    vec3 lam_o = m * vec3(ro.xy, 1.0);
    vec3 lam_d = m * vec3(rd.xy, 0.0);
    float t = sv_graph_patch_hit(b, lam_o, lam_d, ro.z, rd.z, tmin, 3.0e38, 0.0, sv_newton_iterations);
    if (t == SV_NO_HIT) return false;

    hit.t = t;
    hit.pos = ro + hit.t * rd;
    vec3 l = lam_o + hit.t * lam_d;
    float f;
    vec3 a;
    float d[6];
    sv_tri_quartic_jet(b, l, f, a, d);
    vec3 ux = m[0];  // d lam / dx (first column of M)
    vec3 uy = m[1];  // d lam / dy
    float fx = 4.0 * dot(ux, a);
    float fy = 4.0 * dot(uy, a);
    hit.pos.z = f;  // the surface point itself, not the ray's rounding of it
    hit.normal = vec3(-fx, -fy, 1.0);
    hit.scalar = f;
    hit.uv = l.yz;
#ifdef SV_OUT_CURVATURE
    float fxx = sv_tri_quartic_d2(d, ux, ux);
    float fxy = sv_tri_quartic_d2(d, ux, uy);
    float fyy = sv_tri_quartic_d2(d, uy, uy);
    float g = 1.0 + fx * fx + fy * fy;
    float mean = ((1.0 + fy * fy) * fxx - 2.0 * fx * fy * fxy + (1.0 + fx * fx) * fyy) / (2.0 * pow(g, 1.5));
    float gauss = (fxx * fyy - fxy * fxy) / (g * g);
    hit.curvature = vec2(mean, gauss);
#endif
    return true;
}
