// Reflection lines (zebra): a family of parallel light lines, infinitely far away, along the axis a, seen in
// the mirrored view ray r. A line at angle phi around a is hit when atan(r.b, r.c) = phi ((a, b, c) an
// orthonormal frame, sv_line_b and sv_line_c), so stripes of that angle show how the surface bends light; a
// kink in the stripes is a kink in the normal field (G1 break), a kink in their curvature a curvature (G2)
// break. With a = x (the default) b = y and c = z. Dark 0.15, bright 1, filtered over the pixel with
// SV_ANTIALIAS (lib/effects/footprint.glsl): the angle's screen-space rate comes from the chain rule,
// d atan(b, c) = (c db - b dc) / (b^2 + c^2), on the derivatives of r, so it has no jump where atan wraps.
#include "lib/effects/footprint.glsl"
uniform float sv_stripes;  // number of dark/bright pairs over a half turn
uniform vec3 sv_line_b;
uniform vec3 sv_line_c;

float sv_reflection_lines(vec3 r) {
    float rb = dot(r, sv_line_b);
    float rc = dot(r, sv_line_c);
    float x = atan(rb, rc) / 3.141592653589793 * sv_stripes;  // phase in [-1, 1] times the stripe count
#ifdef SV_ANTIALIAS
    vec3 rx = dFdx(r);
    vec3 ry = dFdy(r);
    float scale = sv_stripes / (3.141592653589793 * (rb * rb + rc * rc));
    float w = sv_stripe_footprint(abs(rc * dot(rx, sv_line_b) - rb * dot(rx, sv_line_c)) * scale,
                                  abs(rc * dot(ry, sv_line_b) - rb * dot(ry, sv_line_c)) * scale);
#else
    float w = 0.0;
#endif
    return mix(0.15, 1.0, sv_stripe_bright(x, w));
}
