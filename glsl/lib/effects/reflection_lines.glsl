// Reflection lines: a family of parallel light lines along the model x axis, infinitely far away, seen
// in the mirrored view ray r. A line at angle phi around the x axis is hit when atan(r.y, r.z) = phi, so
// stripes of that angle show how the surface bends light; a kink in the stripes is a kink in the normal
// field (G1 break), a kink in their curvature a curvature (G2) break.
uniform float sv_stripes;  // number of dark/bright pairs over a half turn

float sv_reflection_lines(vec3 r) {
    float phi = atan(r.y, r.z) / 3.141592653589793;  // in [-1, 1]
    return fract(phi * sv_stripes) < 0.5 ? 0.15 : 1.0;
}
