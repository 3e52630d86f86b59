// Reflection lines (zebra): a family of parallel light lines, infinitely far away, along the axis a, seen in
// the mirrored view ray r. A line at angle phi around a is hit when atan(r.b, r.c) = phi ((a, b, c) an
// orthonormal frame, sv_line_b and sv_line_c), so stripes of that angle show how the surface bends light; a
// kink in the stripes is a kink in the normal field (G1 break), a kink in their curvature a curvature (G2)
// break. With a = x (the default) b = y and c = z.
uniform float sv_stripes;  // number of dark/bright pairs over a half turn
uniform vec3 sv_line_b;
uniform vec3 sv_line_c;

float sv_reflection_lines(vec3 r) {
    float phi = atan(dot(r, sv_line_b), dot(r, sv_line_c)) / 3.141592653589793;  // in [-1, 1]
    return fract(phi * sv_stripes) < 0.5 ? 0.15 : 1.0;
}
