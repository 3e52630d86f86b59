// Mean and Gaussian curvature of the bicubic B-spline of a padded geometry image at its samples
// [Losasso2003, sec. 5; DoCarmo1976, sec. 3-3]: a Q x Q control image g^k gives (Q-2) x (Q-2) outputs,
// texel p from the 3 x 3 source texels around p + 1; sv_frag_out0 = (H, K, 0, 0).
// T_s, T_t are the tangent masks of glsl/passes/gi_limit.glsl, P_ss, P_tt = [1 -2 1] x [1 4 1] / 6 and
// P_st = (1/4) [[1 0 -1] [0 0 0] [-1 0 1]]; v = T_s x T_t, D = v . v (= EG - F^2 without its cancellation),
// n = v / sqrt(D), E F G the first and L M N (second derivatives . n) the second fundamental form:
// H = (E N - 2 F M + G L) / (2 D), K = (L N - M^2) / D. Sign as in glsl/programs/nurbs.glsl: H = -1/r on a
// sphere with outward normals.
// At the four cut vertices the tangents vanish (D = 0) and the curvature is unbounded in general
// [Losasso2003, appendix]: the texel holds the mean of the values at the cut vertex's four neighbours in the
// closed mesh (splinevis.geometry_image.image.cut_neighbours), ((a + b) + (c + d)) / 4 -- a finite stand-in,
// not the surface's curvature. CPU twin: splinevis.geometry_image.subdivision.curvature.
uniform sampler2D sv_src;

vec2 sv_gi_curvature(ivec2 c) {  // at the source texel c (padded coordinates)
    vec3 g[9];  // g[3 * (dy + 1) + (dx + 1)] = source at c + (dx, dy)
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            g[3 * (dy + 1) + (dx + 1)] = texelFetch(sv_src, c + ivec2(dx, dy), 0).xyz;
        }
    }
    vec3 ds0 = g[2] - g[0], ds1 = g[5] - g[3], ds2 = g[8] - g[6];
    vec3 ts = ((ds0 + ds2) + 4.0 * ds1) * (1.0 / 12.0);
    vec3 dt0 = g[6] - g[0], dt1 = g[7] - g[1], dt2 = g[8] - g[2];
    vec3 tt = ((dt0 + dt2) + 4.0 * dt1) * (1.0 / 12.0);
    vec3 es0 = (g[0] + g[2]) - 2.0 * g[1], es1 = (g[3] + g[5]) - 2.0 * g[4], es2 = (g[6] + g[8]) - 2.0 * g[7];
    vec3 pss = ((es0 + es2) + 4.0 * es1) * (1.0 / 6.0);
    vec3 et0 = (g[0] + g[6]) - 2.0 * g[3], et1 = (g[1] + g[7]) - 2.0 * g[4], et2 = (g[2] + g[8]) - 2.0 * g[5];
    vec3 ptt = ((et0 + et2) + 4.0 * et1) * (1.0 / 6.0);
    vec3 pst = ((g[8] - g[6]) - (g[2] - g[0])) * 0.25;
    vec3 v = cross(ts, tt);
    float D = dot(v, v);
    vec3 n = v * inversesqrt(D);
    float E = dot(ts, ts), F = dot(ts, tt), G = dot(tt, tt);
    float L = dot(pss, n), M = dot(pst, n), Nn = dot(ptt, n);
    return vec2((E * Nn - 2.0 * F * M + G * L) / (2.0 * D), (L * Nn - M * M) / D);
}

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    ivec2 c = q + 1;
    int N = textureSize(sv_src, 0).x - 3;  // the interior has N + 1 samples per side
    int h = N / 2;
    // at a cut vertex: a along its border, d inwards; neighbours c - a, c + d, c + d - a, c + d + a
    ivec2 a = ivec2(0), d = ivec2(0);
    if (q.x == h && q.y == 0) { a = ivec2(1, 0); d = ivec2(0, 1); }
    else if (q.x == h && q.y == N) { a = ivec2(1, 0); d = ivec2(0, -1); }
    else if (q.y == h && q.x == 0) { a = ivec2(0, 1); d = ivec2(1, 0); }
    else if (q.y == h && q.x == N) { a = ivec2(0, 1); d = ivec2(-1, 0); }
    vec2 k;
    if (d != ivec2(0)) {
        k = ((sv_gi_curvature(c - a) + sv_gi_curvature(c + d))
             + (sv_gi_curvature(c + d - a) + sv_gi_curvature(c + d + a))) * 0.25;
    } else {
        k = sv_gi_curvature(c);
    }
    sv_frag_out0 = vec4(k, 0.0, 0.0);
}
