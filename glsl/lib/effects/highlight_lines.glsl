// Highlight lines [BeierChen1994]: linear lights along the axis E lie in the plane dot(x, m) = h, one every
// sv_highlight_spacing across it (direction W = m x E). A surface point p is lit when its normal line p + s n
// meets a light; the band index is where that line pierces the plane, measured along W. Unlike reflection
// lines they do not depend on the eye: the same surface gives the same bands from every view. Dark 0.15,
// bright 1, filtered over the pixel with SV_ANTIALIAS (lib/effects/footprint.glsl).
#include "lib/effects/footprint.glsl"
uniform vec3 sv_highlight_plane;    // m, unit normal of the plane of lights (model frame)
uniform vec3 sv_highlight_across;   // W, unit, in the plane, across the lights
uniform float sv_highlight_height;  // h, the plane's offset along m (model frame)
uniform float sv_highlight_spacing;
uniform float sv_highlight_shift;   // W . (world - model): bands stay put in the world

float sv_highlight_lines(vec3 p, vec3 n) {
    float dn = dot(n, sv_highlight_plane);
    bool parallel = abs(dn) < 1.0e-6;  // the normal line runs parallel to the plane of lights: unlit
    float s = (sv_highlight_height - dot(p, sv_highlight_plane)) / (parallel ? 1.0 : dn);
    float w = (dot(p + s * n, sv_highlight_across) + sv_highlight_shift) / sv_highlight_spacing;
    float width = sv_stripe_width(w);  // in uniform control flow: the derivatives need the whole pixel quad
    return parallel ? 1.0 : mix(0.15, 1.0, sv_stripe_bright(w, width));
}
