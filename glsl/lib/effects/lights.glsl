// Directional lights (Lambert diffuse, optional Phong specular). Directions point towards the lights,
// in model coordinates; the Python side turns the Style's camera-fixed rig into model coordinates every
// frame, so lights follow the camera as in VTK's light kit.
uniform vec3 sv_light_dir[SV_NUM_LIGHTS];
#ifdef SV_SPECULAR
uniform float sv_specular_power;
#ifdef SV_ANTIALIAS
// A highlight narrower than the pixel (a bumpy or steep surface seen from afar) sparkles when one normal
// stands for the pixel. Toksvig's filtered specular [Toksvig2005, eq. 4-5] widens it by the spread of the
// normals over the pixel: the mean of the unit normals over the footprint has length
// |Na| = 1 - sigma^2 / 2, sigma^2 = (|dn/dX|^2 + |dn/dY|^2) / 12 (a linear field over a unit box; the twin:
// splinevis.analysis.footprint.toksvig_factor), and the lobe exponent s becomes ft s with
// ft = |Na| / (|Na| + s (1 - |Na|)), its height scaled by (1 + ft s) / (1 + s) to keep the lobe's energy.
#include "lib/effects/footprint.glsl"
float sv_toksvig_factor(vec3 n, float s) {
    vec3 nx = dFdx(n);
    vec3 ny = dFdy(n);
    float vx = dot(nx, nx);
    float vy = dot(ny, ny);
    bool bad_x = dFdx(sv_footprint_valid) != 0.0;  // a quad neighbour missed: its normal is not this surface's
    bool bad_y = dFdy(sv_footprint_valid) != 0.0;
    if (bad_x && bad_y) return 1.0;
    if (bad_x) vx = vy;
    if (bad_y) vy = vx;
    float na = max(1.0 - (vx + vy) / 24.0, 0.0);
    return na / (na + s * (1.0 - na));
}
#endif
#endif

vec3 sv_lights(vec3 n, vec3 v, vec3 base) {
    vec3 c = sv_ambient * base;
#ifdef SV_SPECULAR
    float s = sv_specular_power;
    float height = 0.5;
#ifdef SV_ANTIALIAS
    float ft = sv_toksvig_factor(n, sv_specular_power);  // uniform control flow: before the loop's branches
    s = ft * sv_specular_power;
    height = 0.5 * (1.0 + s) / (1.0 + sv_specular_power);
#endif
#endif
    for (int i = 0; i < SV_NUM_LIGHTS; ++i) {
        vec3 l = sv_light_dir[i];
        float d = max(dot(n, l), 0.0);
        c += sv_diffuse * d * base / float(SV_NUM_LIGHTS);
#ifdef SV_SPECULAR
        if (d > 0.0) c += vec3(height) * pow(max(dot(reflect(-l, n), v), 0.0), s);
#endif
    }
    return c;
}
