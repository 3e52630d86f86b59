// Isophotes: curves of constant dot(n, L) for the first light, drawn as alternating bands.
uniform float sv_isophote_bands;

float sv_isophotes(vec3 n) {
    float c = clamp(dot(n, sv_light_dir[0]), -1.0, 1.0);
    return fract(c * sv_isophote_bands) < 0.5 ? 0.2 : 1.0;
}
