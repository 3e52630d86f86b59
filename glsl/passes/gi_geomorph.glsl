// Continuous level of detail k + alpha [Losasso2003, sec. 5]: the coarse level (n x n) linearly subdivided
// on the triangulation whose diagonals join (r, c) and (r+1, c+1) -- texel p takes the midpoint of the
// coarse samples p / 2 and p / 2 + (p mod 2) -- blended with the fine level ((2n-1) x (2n-1)):
// (1 - alpha) lin + alpha fine, normalized when sv_unit != 0 (normals; xyz, w = 0).
// CPU twin: splinevis.geometry_image.subdivision.geomorph.
uniform sampler2D sv_fine;
uniform sampler2D sv_coarse;
uniform float sv_alpha;
uniform int sv_unit;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 I = p / 2;
    vec4 lin = 0.5 * texelFetch(sv_coarse, I, 0) + 0.5 * texelFetch(sv_coarse, I + (p - 2 * I), 0);
    vec4 v = (1.0 - sv_alpha) * lin + sv_alpha * texelFetch(sv_fine, p, 0);
    if (sv_unit != 0) {
        float len2 = dot(v.xyz, v.xyz);
        v = vec4(len2 > 0.0 ? v.xyz * inversesqrt(len2) : vec3(0.0), 0.0);
    }
    sv_frag_out0 = v;
}
