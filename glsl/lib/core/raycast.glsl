// Shared skeleton of every ray-cast program (analytic patch, terrain, isosurface, NURBS).
//
// A program file defines
//     bool sv_surface_hit(vec3 ro, vec3 rd, float tmin, out SvHit hit);
// which fills hit.pos (model coordinates), hit.normal (not necessarily unit), hit.scalar (the value a
// colormap shows: height for graph surfaces), hit.uv (texture coordinates in [0,1]^2), hit.t, and --
// only when SV_OUT_CURVATURE is defined -- hit.curvature = (mean, gaussian).
// The proxy geometry is rasterized with front faces culled, so each fragment lies on the far side of
// the proxy and the camera may sit inside it.

// The "no hit" ray parameter of every program (larger than any real t).
const float SV_NO_HIT = 3.0e38;

struct SvHit {
    vec3 pos;
    vec3 normal;
    float scalar;
    vec2 uv;
    float t;
    float depth;
    vec2 curvature;
};
#ifdef SV_DEBUG_COUNTERS
#include "lib/core/counters.glsl"
#endif

uniform vec3 sv_eye_mc;       // camera position, model coordinates (perspective views)
uniform vec3 sv_view_dir_mc;  // unit view direction, model coordinates (parallel views)
uniform int sv_parallel;      // 1 for a parallel projection
uniform vec3 sv_color;        // base colour when neither colormap nor texture is declared
uniform float sv_ambient;     // lighting weights (lib/effects/lights.glsl)
uniform float sv_diffuse;

// The viewing ray through this fragment: origin, unit direction and the smallest admissible parameter.
// The origin is the fragment's own position on the proxy (its far side), not the eye: everything the
// program computes then involves coordinates of the size of the proxy, and a distant eye (a grazing view
// across a terrain from kilometres away) costs no float32 precision. Perspective rays start at the eye,
// which lies at t = -|pos - eye|; parallel rays come from -infinity.
void sv_pixel_ray(vec3 pos_mc, out vec3 ro, out vec3 rd, out float tmin) {
    ro = pos_mc;
    if (sv_parallel == 1) {
        rd = sv_view_dir_mc;
        tmin = -3.0e38;
    } else {
        vec3 v = pos_mc - sv_eye_mc;
        rd = normalize(v);
        tmin = -length(v);
    }
}

// Window depth of a model-space point: clip coordinates through VTK's MCDCMatrix, then the depth range
// (OpenGL 4.5 spec, section 13.8.1); this is what lets the ray-cast surface composite with meshes.
float sv_window_depth(mat4 mcdc, vec3 p) {
    vec4 clip = mcdc * vec4(p, 1.0);
    float ndc_z = clip.z / clip.w;
    return 0.5 * (gl_DepthRange.diff * ndc_z + gl_DepthRange.near + gl_DepthRange.far);
}
