// A toy ray-cast program outside the package: the sphere |p| = sv_toy_radius (model frame centred on it).
// It includes the shipped library like any built-in program (tests/test_toy_family.py).
#include "lib/core/raycast.glsl"

uniform float sv_toy_radius;

bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit) {
    // |ro + t rd|^2 = r^2 with |rd| = 1: t^2 + 2 b t + c = 0; the smaller root without cancellation
    float b = dot(ro, rd);
    float c = dot(ro, ro) - sv_toy_radius * sv_toy_radius;
    float disc = b * b - c;
    if (disc < 0.0) return false;
    float q = -(b + (b >= 0.0 ? sqrt(disc) : -sqrt(disc)));
    float t0 = q == 0.0 ? 0.0 : c / q;
    float t1 = q;
    float t = min(t0, t1);
    if (t < tmin) t = max(t0, t1);
    if (t < tmin) return false;
    hit.t = t;
    hit.pos = ro + t * rd;
    hit.normal = hit.pos;
    hit.scalar = hit.pos.z;
    hit.uv = vec2(0.5) + 0.5 * hit.pos.xy / sv_toy_radius;
    hit.depth = 0.0;
    hit.curvature = vec2(1.0 / sv_toy_radius, 1.0 / (sv_toy_radius * sv_toy_radius));
    return true;
}
