// Ray casting the isosurface s = isovalue of a quadratic or cubic spline on the type-6 partition, per
// fragment (paper 003, sec. 5).
//
// Proxy: one box per relevant cube (splinevis.volume.program), rasterized with front faces culled, so
// each fragment lies on the cube's far side and the camera may be inside the volume. The fragment tests
// the relevant tetrahedra of its own cube (bit mask, a flat vertex attribute):
// 1. clip the ray by the tetrahedron's barycentric coordinates (paper 003, sec. 5.3: lam_i >= 0), with
//    margins against cracks between neighbours (a wide one across the cube's faces, where neighbouring
//    fragments round the ray independently and the splines are C1, and a narrow one inside the cube);
// 2. BB coefficients of s on the tetrahedron: recomputed from the cube's 27 data values with the scheme's
//    averaging rules (encoding "data", the determining data of paper 003 sec. 5.1 taken to the limit: one
//    value per cube) or read from a table (encoding "coefficients": every coefficient stored);
// 3. restriction to the segment by blossoming (Fig. 10), isovalue subtracted, first root in [0, 1]:
//    quadratic by the stable closed form, cubic by bracketed Newton (default) or paper 003's Newton from
//    three starts (SV_ROOTS_PAPER_NEWTON);
// 4. the smallest t over the tetrahedra wins in the cube; across cubes the depth test picks the first.
// Normal: gradient of s from the degree n - 1 coefficients at the hit (paper 003, sec. 5.3, last para).
// The float64 twin is splinevis.volume.raycast.
#include "lib/raycast.glsl"
#include "lib/roots.glsl"
#include "lib/type6.glsl"
#include "lib/tet_steps.glsl"
#ifdef SV_VOLUME_CUBIC
#include "lib/volume_stencil_cubic.glsl"
#else
#include "lib/volume_stencil_quadratic.glsl"
#endif

uniform vec3 sv_inv_spacing;      // index-space direction = sv_inv_spacing * model-space direction
uniform float sv_iso_shifted;     // isovalue - sv_value_ref (the textures hold data - sv_value_ref)
uniform float sv_value_ref;
uniform int sv_newton_iterations;
uniform float sv_cube_margin;     // clip margins in barycentric units: lam_0 (the face on the cube's boundary)
uniform float sv_inner_margin;    // and lam_1..3 (faces inside the cube), see splinevis.volume.program
uniform int sv_tex_width;         // texels per row of the data / coefficient texture
uniform vec3 sv_padded_dims;      // (nx + 2, ny + 2, nz + 2)
uniform vec3 sv_cube_count;       // (nx, ny, nz): hit.uv = (x, y) / (nx, ny)

#ifdef SV_VOLUME_COLOR_FIELD
// A second field on the same grid (the sampler sv_color_data, same layout as sv_volume_data): the
// isosurface is coloured by its spline (same scheme) at the hit; hit.scalar feeds the colormap effect.
float sv_fetch_color(int n) {
    int texel = n / 4;
    vec4 v = texelFetch(sv_color_data, ivec2(texel % sv_tex_width, texel / sv_tex_width), 0);
    return v[n - 4 * texel];
}
#endif

float sv_fetch_linear(int n) {
    int texel = n / 4;
#ifdef SV_VOLUME_TABLE
    vec4 v = texelFetch(sv_volume_coef, ivec2(texel % sv_tex_width, texel / sv_tex_width), 0);
#else
    vec4 v = texelFetch(sv_volume_data, ivec2(texel % sv_tex_width, texel / sv_tex_width), 0);
#endif
    return v[n - 4 * texel];
}

#ifdef SV_VOLUME_TABLE
// Coefficients of the cube's r-th relevant tetrahedron, row (first row of the cube) + r of the table.
void sv_load_tet(int t, int r, float f[27], out float b[SV_VOL_NCOEF]) {
    int row = 4096 * int(sv_cube_extraVSOut.y + 0.5) + int(sv_cube_extraVSOut.z + 0.5);
    int base = (row + r) * SV_VOL_NCOEF;
    for (int q = 0; q < SV_VOL_NCOEF; ++q) b[q] = sv_fetch_linear(base + q);
}
#else
void sv_load_tet(int t, int r, float f[27], out float b[SV_VOL_NCOEF]) {
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

void sv_load_stencil(ivec3 c, out float f[27]) {
#ifdef SV_VOLUME_TABLE
    for (int s = 0; s < 27; ++s) f[s] = 0.0;
#else
    sv_load_stencil_of(c, 0, f);
#endif
}

float sv_first_root_deg(float c[5]) {
#if !defined(SV_VOLUME_CUBIC) && !defined(SV_ROOTS_PAPER_NEWTON) && !defined(SV_ROOTS_BRACKETED)
    return sv_first_root_quadratic(c);
#else
    return sv_first_root(c, SV_VOL_DEGREE, sv_newton_iterations);
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
// mean = (|g|^2 tr H - g^T H g) / (2 |g|^3), gauss = g^T adj(H) g / |g|^4 (Goldman, CAGD 22 (2005)):
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

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    hit.curvature = vec2(0.0);
    hit.depth = 0.0;
    ivec3 c = ivec3(sv_cubeVSOut.xyz + 0.5);
    int mask = int(sv_cubeVSOut.w + 0.5) + 4096 * int(sv_cube_extraVSOut.x + 0.5);
    // The ray in cube-local coordinates: the interpolated local position of this fragment (exact at the
    // proxy's corners) and the direction in index units; t is the model-space parameter of ro + t rd.
    vec3 P0 = sv_localVSOut;
    vec3 D = sv_inv_spacing * rd;
    float f[27];
    sv_load_stencil(c, f);
    float t_best = SV_NO_HIT;
    int tet_best = -1;
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
        sv_load_tet(t, rank, f, b);
        float cc[5];
        sv_restrict(b, lo + ta * ld, lo + tb * ld, cc);
        for (int k = 0; k <= SV_VOL_DEGREE; ++k) cc[k] -= sv_iso_shifted;
        float s = sv_first_root_deg(cc);
        if (s < 0.0) continue;
        float th = ta + s * (tb - ta);
        if (th < t_best) {
            t_best = th;
            tet_best = t;
            hit.uv = vec2(float(rank), 0.0);  // remembered for the normal below
        }
    }
    if (tet_best < 0) return false;

    float b[SV_VOL_NCOEF];
    sv_load_tet(tet_best, int(hit.uv.x + 0.5), f, b);
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
