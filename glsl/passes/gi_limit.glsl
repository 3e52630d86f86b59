// Limit positions and unit normals of a padded geometry image [Losasso2003, sec. 5, Table 1]: a Q x Q
// control image g^k gives (Q-2) x (Q-2) outputs, texel p from the 3 x 3 source texels around p + 1.
//   sv_frag_out0: E[g] = [1 4 1]^T [1 4 1] / 36 (all four channels)
//   sv_frag_out1: unit(T_s x T_t) in xyz (w = 0), T_s = d/ds along a row (x), T_t = d/dt across rows (y);
//                 at the four cut vertices (the border midpoints of the interior, eq. 1) the tangents
//                 vanish and the normal is sv_cut_normal[i], in the order of
//                 splinevis.geometry_image.image.cut_vertices (top row, bottom row, left column, right
//                 column): unit(P_ss x P_st + P_st x P_tt) computed once in float64 from the level-0 image
//                 (the same point and normal at every level; in float32 its second differences would lose
//                 4^k of the precision at level k). A zero vector gives a zero normal.
// Rounding: the limit mask sums 9 terms with exact integer weights (<= 8 roundings in any order), then one
// multiplication by the rounded constant 1/36 (2 more). CPU twin: splinevis.geometry_image.subdivision
// (limit, tangents, cut_normals, normals).
uniform sampler2D sv_src;
uniform vec3 sv_cut_normal[4];

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    ivec2 c = q + 1;
    vec4 g[9];  // g[3 * (dy + 1) + (dx + 1)] = source at c + (dx, dy)
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            g[3 * (dy + 1) + (dx + 1)] = texelFetch(sv_src, c + ivec2(dx, dy), 0);
        }
    }
    vec4 r0 = (g[0] + g[2]) + 4.0 * g[1];
    vec4 r1 = (g[3] + g[5]) + 4.0 * g[4];
    vec4 r2 = (g[6] + g[8]) + 4.0 * g[7];
    sv_frag_out0 = ((r0 + r2) + 4.0 * r1) * (1.0 / 36.0);

    int N = textureSize(sv_src, 0).x - 3;  // the interior has N + 1 samples per side
    int h = N / 2;
    int cut = q.x == h ? (q.y == 0 ? 0 : (q.y == N ? 1 : -1)) : (q.y == h ? (q.x == 0 ? 2 : (q.x == N ? 3 : -1)) : -1);
    if (cut >= 0) {
        sv_frag_out1 = vec4(sv_cut_normal[cut], 0.0);
        return;
    }
    vec3 ds0 = g[2].xyz - g[0].xyz, ds1 = g[5].xyz - g[3].xyz, ds2 = g[8].xyz - g[6].xyz;
    vec3 ts = ((ds0 + ds2) + 4.0 * ds1) * (1.0 / 12.0);
    vec3 dt0 = g[6].xyz - g[0].xyz, dt1 = g[7].xyz - g[1].xyz, dt2 = g[8].xyz - g[2].xyz;
    vec3 tt = ((dt0 + dt2) + 4.0 * dt1) * (1.0 / 12.0);
    vec3 v = cross(ts, tt);
    float len2 = dot(v, v);
    sv_frag_out1 = vec4(len2 > 0.0 ? v * inversesqrt(len2) : vec3(0.0), 0.0);
}
