// Directional lights (Lambert diffuse, optional Phong specular). Directions point towards the lights,
// in model coordinates; the Python side turns the Style's camera-fixed rig into model coordinates every
// frame, so lights follow the camera as in VTK's light kit.
uniform vec3 sv_light_dir[SV_NUM_LIGHTS];
#ifdef SV_SPECULAR
uniform float sv_specular_power;
#endif

vec3 sv_lights(vec3 n, vec3 v, vec3 base) {
    vec3 c = sv_ambient * base;
    for (int i = 0; i < SV_NUM_LIGHTS; ++i) {
        vec3 l = sv_light_dir[i];
        float d = max(dot(n, l), 0.0);
        c += sv_diffuse * d * base / float(SV_NUM_LIGHTS);
#ifdef SV_SPECULAR
        if (d > 0.0) c += vec3(0.5) * pow(max(dot(reflect(-l, n), v), 0.0), sv_specular_power);
#endif
    }
    return c;
}
