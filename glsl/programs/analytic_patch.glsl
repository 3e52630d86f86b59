// Ray casting one quartic BB triangle patch z = f(x, y) (the foundation's analytic test surface and the
// per-patch core of the terrain program; paper 000, sec. V-VI).
//
// 1. Clip the ray against the prism over the triangle between the smallest and largest coefficient
//    (the convex-hull property bounds f there).
// 2. Restrict f to the projected segment by blossoming (paper 000, eq. (6)-(7)): five univariate BB
//    coefficients; subtract the ray's height, itself degree-elevated to a quartic.
// 3. First root in [0,1] (lib/roots.glsl sv_first_root): bracketed Newton on convex pieces, or paper
//    000's Newton from secure starting points when SV_ROOTS_PAPER_NEWTON is defined.
// 4. Value, gradient (and Hessian for curvature) by de Casteljau at the hit (lib/bb_triangle.glsl).
#include "lib/raycast.glsl"
#include "lib/bb_triangle.glsl"
#include "lib/blossom.glsl"
#include "lib/roots.glsl"

#ifdef SV_PATCH_TEXTURE
// Coefficients from an RGBA32F table (VTK declares the sampler sv_patch_coeffs): row = patch id, texels
// 0..3 hold the 15 coefficients (+1 padding). The patch id is a flat vertex attribute of the proxy.
// This is the path terrains and volumes use for millions of patches; here it proves the plumbing.
void sv_patch_load(out float b[15]) {
    int row = int(sv_patch_idVSOut + 0.5);
    for (int q = 0; q < 4; ++q) {
        vec4 v = texelFetch(sv_patch_coeffs, ivec2(q, row), 0);
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
uniform vec2 sv_patch_zrange;       // (min, max) of the coefficients: the prism's bottom and top
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
    float t0 = tmin;
    float t1 = 3.0e38;
    for (int i = 0; i < 3; ++i) {
        if (abs(lam_d[i]) < 1e-30) {
            if (lam_o[i] < 0.0) return false;
        } else {
            float tc = -lam_o[i] / lam_d[i];
            if (lam_d[i] > 0.0) t0 = max(t0, tc); else t1 = min(t1, tc);
        }
    }
    // Slab widened by ~16 ulps of the heights involved (a flat patch must not collapse it to a point).
    float zpad = 1.0e-6 * (max(abs(sv_patch_zrange.x), abs(sv_patch_zrange.y)) + abs(ro.z)) + 1.0e-30;
    float zlo = sv_patch_zrange.x - zpad;
    float zhi = sv_patch_zrange.y + zpad;
    if (abs(rd.z) < 1e-30) {
        if (ro.z < zlo || ro.z > zhi) return false;
    } else {
        float ta = (zlo - ro.z) / rd.z;
        float tb = (zhi - ro.z) / rd.z;
        t0 = max(t0, min(ta, tb));
        t1 = min(t1, max(ta, tb));
    }
    if (!(t0 <= t1)) return false;

    vec3 l0 = lam_o + t0 * lam_d;
    vec3 l1 = lam_o + t1 * lam_d;
    float c[5];
    sv_restrict_quartic_tri(b, l0, l1, c);
    float z0 = ro.z + t0 * rd.z;
    float z1 = ro.z + t1 * rd.z;
    for (int k = 0; k < 5; ++k) c[k] -= mix(z0, z1, float(k) / 4.0);
    // Convex hull property: no sign change among the coefficients, no root on the segment (the common
    // case for cells the hierarchy could not rule out); skip the root finder.
    float cmin = min(min(min(c[0], c[1]), min(c[2], c[3])), c[4]);
    float cmax = max(max(max(c[0], c[1]), max(c[2], c[3])), c[4]);
    if (cmin > 0.0 || cmax < 0.0) return false;
    float s = sv_first_root(c, 4, sv_newton_iterations);
    if (s < 0.0) return false;

    hit.t = mix(t0, t1, s);
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
