// A curvature of the hit through a blue-white-red diverging map; sv_curvature_scale is the value shown as
// full colour. The program computes hit.curvature = (mean H, Gaussian K) only when this effect is declared;
// sv_curvature_kind picks what is shown (a uniform: no recompilation): 0 mean H, 1 Gaussian K,
// 2 maximum principal k1 = H + sqrt(H^2 - K), 3 minimum principal k2 = H - sqrt(H^2 - K),
// 4 the larger |k| (max(|k1|, |k2|), signed).
uniform float sv_curvature_scale;
uniform int sv_curvature_kind;

float sv_curvature_value(vec2 k) {
    float d = sqrt(max(k.x * k.x - k.y, 0.0));
    if (sv_curvature_kind == 1) return k.y;
    if (sv_curvature_kind == 2) return k.x + d;
    if (sv_curvature_kind == 3) return k.x - d;
    if (sv_curvature_kind == 4) return abs(k.x + d) >= abs(k.x - d) ? k.x + d : k.x - d;
    return k.x;
}

vec3 sv_curvature_color(vec2 k) {
    float x = clamp(sv_curvature_value(k) / sv_curvature_scale, -1.0, 1.0);
    vec3 white = vec3(1.0);
    return x < 0.0 ? mix(white, vec3(0.23, 0.30, 0.75), -x) : mix(white, vec3(0.71, 0.02, 0.15), x);
}
