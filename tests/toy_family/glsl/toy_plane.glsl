// A toy "surface"-kind program: the parallelogram S(u, v) = p0 + u e1 + v e2, evaluated at the parameters the
// rasterized mesh carries (the interpolated varying sv_uv), as a NURBS program evaluates its surface.
#include "lib/core/raycast.glsl"

uniform vec3 sv_toy_p0;
uniform vec3 sv_toy_e1;
uniform vec3 sv_toy_e2;

bool sv_surface_eval(vec3 pos_mc, out SvHit hit) {
    vec2 uv = sv_uvVSOut;
    hit.pos = sv_toy_p0 + uv.x * sv_toy_e1 + uv.y * sv_toy_e2;
    hit.normal = cross(sv_toy_e1, sv_toy_e2);
    hit.scalar = hit.pos.z;
    hit.uv = uv;
    hit.t = 0.0;
    hit.depth = 0.0;
    hit.curvature = vec2(0.0);
    return true;
}
