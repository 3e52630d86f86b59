// Scalar displacement along the normal [Losasso2003, sec. 5]: p + d n with the limit positions p (xyz),
// unit normals n (xyz) and the displacement d (channel 0), all of one size; w is p's.
// CPU twin: splinevis.geometry_image.subdivision.displace.
uniform sampler2D sv_p;
uniform sampler2D sv_n;
uniform sampler2D sv_d;

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(sv_p, q, 0);
    vec3 n = texelFetch(sv_n, q, 0).xyz;
    float d = texelFetch(sv_d, q, 0).x;
    sv_frag_out0 = vec4(p.xyz + d * n, p.w);
}
