// NURBS surfaces drawn per fragment [Kanai2007, sec. 3]: a coarse tessellation carries each vertex's
// parameters (u, v) (the interpolated varying sv_nurbs_uvVSOut) and its patch id (the flat attribute
// sv_nurbs_patchVSOut). The interpolated parameters are only a start: Newton on the pixel's ray, written as
// the meet of two planes n1 . x = n1 . ro and n2 . x = n2 . ro, solves F(u, v) = (n1 . (S - ro), n2 . (S - ro)) = 0
// in at most sv_newton_iterations steps (leaving one step after the residual is accepted), so depth and silhouette are those of the surface, not of the tessellation.
// A fragment whose parameters leave the patch domain or whose residual stays above the float32 evaluation
// tolerance is discarded. Parameters are kept in the domain during the iteration (wrapped across a closed
// seam; a step that would cross an open edge goes half way to it), so a ray that misses the patch ends with a
// large residual.
#include "lib/core/raycast.glsl"
#include "lib/nurbs/basis.glsl"
#ifdef SV_NURBS_POLE_TABLES
#include "lib/nurbs/poles.glsl"
#endif
#ifdef SV_NURBS_TRIM
#include "lib/nurbs/trim.glsl"
// sv_trim_index (declared by VTK): per patch (first piece / 4096, first piece % 4096, piece count, -)
#endif

uniform int sv_newton_iterations;

const float SV_NURBS_U32 = 5.9604645e-08;  // 2^-24

vec2 sv_nurbs_into_domain(vec2 uv, vec2 lo, vec2 hi, SvNurbsPatch P) {
    vec2 span = hi - lo;
    if (P.closed_u) uv.x = lo.x + mod(uv.x - lo.x, span.x);
    if (P.closed_v) uv.y = lo.y + mod(uv.y - lo.y, span.y);
    return clamp(uv, lo, hi);
}

// Acceptance threshold on the residual (splinevis.nurbs.raycast.residual_tolerance): twice the float32 error
// of S (basis sums and the rational quotient, gamma_{6(p+q)+8} M; knots rounded: u |U|max (|S_u| + |S_v|)) and
// of the residual itself (8 u (M + |ro|)).
float sv_nurbs_tolerance(SvNurbsPatch P, vec3 Su, vec3 Sv, vec3 ro) {
    float eps_s = float(6 * (P.p + P.q) + 8) * SV_NURBS_U32 * P.magnitude
                + SV_NURBS_U32 * P.knot_max * (length(Su) + length(Sv));
    return 2.0 * (eps_s + 8.0 * SV_NURBS_U32 * (P.magnitude + length(ro)));
}

// uv - lambda step with lambda <= 1 the largest that goes at most half way to an open edge: never onto it (a
// collapsed edge, a pole, has S_u = 0 and would stop the iteration); splinevis.nurbs.raycast.EDGE_STEP. A step
// over a pole of a patch closed in the other parameter goes on over the pole (splinevis.nurbs.raycast._step):
// half a turn on where the pole has half-turn symmetry (exact there), else to the antipodal meridian of the
// step's end (lib/nurbs/poles.glsl, derivation in splinevis/nurbs/poles.py).
vec2 sv_nurbs_step(vec2 uv, vec2 step, vec2 lo, vec2 hi, SvNurbsPatch P) {
    float lam = 1.0;
    vec2 nw = uv - step;
    bvec2 open_edge = bvec2(!P.closed_u, !P.closed_v);
    bvec2 closed = not(open_edge);
    for (int i = 0; i < 2; ++i) {
        if (!open_edge[i]) continue;
        int o = 1 - i;
        if (closed[o]) {  // over a pole of a patch closed the other way: on along the meridian, on the far side
            bool over_lo = nw[i] < lo[i] && (P.poles & (1 << (2 * i))) != 0;
            bool over_hi = nw[i] > hi[i] && (P.poles & (2 << (2 * i))) != 0;
            if (over_lo || over_hi) {
                float end = over_lo ? lo[i] : hi[i];
                int edge = 2 * i + (over_lo ? 0 : 1);
#ifdef SV_NURBS_POLE_TABLES
                if ((P.poles & (16 << edge)) == 0) {  // half-turn symmetry: exact as it stands
#endif
                    uv[i] = 2.0 * end - uv[i];
                    step[i] = -step[i];
                    uv[o] += 0.5 * (hi[o] - lo[o]);
#ifdef SV_NURBS_POLE_TABLES
                } else {  // uv - step = (end + rho (end - nw), t'): t' the antipode of the step's end nw[o]
                    vec2 c = sv_nurbs_cross_pole(P, edge, nw[o], lo[o], hi[o]);
                    uv[i] = end + (end - uv[i]) * c.y;
                    step[i] = -step[i] * c.y;
                    uv[o] = c.x + step[o];
                }
#endif
                nw = uv - step;
            }
        }
        if (nw[i] < lo[i]) lam = min(lam, 0.5 * (uv[i] - lo[i]) / (uv[i] - nw[i]));
        if (nw[i] > hi[i]) lam = min(lam, 0.5 * (hi[i] - uv[i]) / (nw[i] - uv[i]));
    }
    return sv_nurbs_into_domain(uv - lam * step, lo, hi, P);
}

bool sv_surface_eval(vec3 pos_mc, out SvHit hit) {
    vec3 ro; vec3 rd; float tmin;
    sv_pixel_ray(pos_mc, ro, rd, tmin);
    SvNurbsPatch P = sv_nurbs_patch(int(sv_nurbs_patchVSOut + 0.5));
    vec2 lo = vec2(sv_nurbs_knot(P.ku, P.p), sv_nurbs_knot(P.kv, P.q));
    vec2 hi = vec2(sv_nurbs_knot(P.ku, P.nu), sv_nurbs_knot(P.kv, P.nv));
    // the two planes through the ray
    vec3 a = abs(rd.x) < 0.57735 ? vec3(1.0, 0.0, 0.0) : (abs(rd.y) < 0.57735 ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
    vec3 n1 = normalize(cross(rd, a));
    vec3 n2 = cross(rd, n1);
    vec2 uv = sv_nurbs_into_domain(sv_nurbs_uvVSOut, lo, hi, P);
    vec3 S; vec3 Su; vec3 Sv; vec3 Suu; vec3 Suv; vec3 Svv;
    for (int k = 0; k < 16; ++k) {
        if (k >= sv_newton_iterations) break;
        sv_nurbs_surface(P, uv, S, Su, Sv, Suu, Suv, Svv);
        vec3 e = S - ro;
        vec2 F = vec2(dot(n1, e), dot(n2, e));
        float j11 = dot(n1, Su); float j12 = dot(n1, Sv);
        float j21 = dot(n2, Su); float j22 = dot(n2, Sv);
        float det = j11 * j22 - j12 * j21;
        if (det == 0.0) break;
        vec2 step = vec2(j22 * F.x - j12 * F.y, -j21 * F.x + j11 * F.y) / det;
        uv = sv_nurbs_step(uv, step, lo, hi, P);
        if (length(F) <= sv_nurbs_tolerance(P, Su, Sv, ro)) break;  // accepted already: this was the last step
    }
    sv_nurbs_surface(P, uv, S, Su, Sv, Suu, Suv, Svv);
    vec3 e = S - ro;
    float residual = length(vec2(dot(n1, e), dot(n2, e)));
    float tol = sv_nurbs_tolerance(P, Su, Sv, ro);
    if (!(residual <= tol)) return false;
#ifdef SV_NURBS_TRIM
    {   // trimmed away: no hit here (the depth test lets a fragment of a surface further back show)
        vec4 ti = texelFetch(sv_trim_index, sv_table_address(int(sv_nurbs_patchVSOut + 0.5)), 0);
        if (!sv_trim_inside(int(ti.x) * 4096 + int(ti.y), int(ti.z), uv)) return false;
    }
#endif
    hit.pos = S;
    vec3 n = cross(Su, Sv);
    if (dot(n, n) <= 1e-12 * dot(Su, Su) * dot(Sv, Sv) || dot(n, n) == 0.0) {
        // a degenerate point (a pole, a collapsed row): the first non-vanishing term of S_u(u+h) x S_v(v+k)
        n = cross(Su, Suv) + cross(Suv, Sv);
        if (dot(n, n) == 0.0) n = cross(Su, Svv);
        if (dot(n, n) == 0.0) n = cross(Suu, Sv);
        if (dot(n, n) == 0.0) n = cross(Suu, Svv);
    }
    hit.normal = n;
    hit.scalar = S.z;
    hit.uv = (uv - lo) / (hi - lo);
    hit.t = dot(S - ro, rd);
    hit.depth = 0.0;
    hit.curvature = vec2(0.0);
#ifdef SV_OUT_CURVATURE
    vec3 nu = normalize(n);
    float E = dot(Su, Su); float Fm = dot(Su, Sv); float G = dot(Sv, Sv);
    float L = dot(Suu, nu); float M = dot(Suv, nu); float Nn = dot(Svv, nu);
    float den = E * G - Fm * Fm;
    hit.curvature = vec2((E * Nn - 2.0 * Fm * M + G * L) / (2.0 * den), (L * Nn - M * M) / den);
#endif
    return true;
}
