// Isophotes: curves of constant dot(n, L) for the first light, drawn as alternating bands (dark 0.2, bright 1),
// filtered over the pixel with SV_ANTIALIAS (lib/effects/footprint.glsl).
#include "lib/effects/footprint.glsl"
uniform float sv_isophote_bands;

float sv_isophotes(vec3 n) {
    float x = clamp(dot(n, sv_light_dir[0]), -1.0, 1.0) * sv_isophote_bands;
    return mix(0.2, 1.0, sv_stripe_bright(x, sv_stripe_width(x)));
}
