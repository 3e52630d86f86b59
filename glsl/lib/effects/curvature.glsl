// Mean curvature through a blue-white-red diverging map; sv_curvature_scale is the |H| shown as full
// colour. The program computes hit.curvature = (mean, gaussian) only when this effect is declared.
uniform float sv_curvature_scale;

vec3 sv_curvature_color(vec2 k) {
    float x = clamp(k.x / sv_curvature_scale, -1.0, 1.0);
    vec3 white = vec3(1.0);
    return x < 0.0 ? mix(white, vec3(0.23, 0.30, 0.75), -x) : mix(white, vec3(0.71, 0.02, 0.15), x);
}
