// The continuation of a Newton step over a pole (a collapsed edge) of a patch closed in the other parameter,
// where the pole has no half-turn symmetry (header bit 16 << edge). Derivation in splinevis/nurbs/poles.py:
// at the pole, S_v(t, v_p) = +-c C(t) / w0(t) with C(t) = sum_i N_i(t) w_ir (P_ir - P_pole) (r the row next to
// the pole), so the meridian t continued through the pole arrives on the meridian t' with C(t') || -C(t)
// (about the pole normal n), at rho = (|C(t)| / w0(t)) / (|C(t')| / w0(t')) times its distance beyond the pole.
// t' from a per-pole table of t'(t_k) - t_k (splinevis.nurbs.poles.pole_table, in sv_nurbs_knots after the
// patch's V knots: n, then SV_NURBS_POLE_TABLE + 1 values) and one Newton step on the angle, clamped to a
// table step. splinevis.nurbs.poles.cross_pole is the float64 twin, step for step.
#include "lib/nurbs/basis.glsl"

const int SV_NURBS_POLE_TABLE = 64;  // splinevis.nurbs.poles.POLE_TABLE

// C(t), C'(t) and the pole row's weight w0(t) along edge `edge` (0: u=lo, 1: u=hi, 2: v=lo, 3: v=hi).
void sv_nurbs_pole_curve(SvNurbsPatch P, int edge, float t, out vec3 C, out vec3 dC, out float w0) {
    int axis = edge / 2;
    bool hi_end = (edge - 2 * axis) == 1;
    int ko = axis == 0 ? P.kv : P.ku;  // t runs along the edge: v for the u edges, u for the v edges
    int deg = axis == 0 ? P.q : P.p;
    int span = sv_nurbs_find_span(ko, deg, axis == 0 ? P.nv : P.nu, t);
    float N[SV_NURBS_ORDER]; float D[SV_NURBS_ORDER]; float DD[SV_NURBS_ORDER];
    sv_nurbs_basis(ko, span, deg, t, N, D, DD);
    int stride = axis == 0 ? 1 : P.nv;
    int across = axis == 0 ? P.nu : P.nv;
    int pole_row = hi_end ? across - 1 : 0;
    int near_row = hi_end ? across - 2 : 1;
    int pole0 = P.cp + (axis == 0 ? pole_row * P.nv : pole_row);
    int near0 = P.cp + (axis == 0 ? near_row * P.nv : near_row);
    vec4 Pp = sv_table_texel(sv_nurbs_cps, pole0);
    vec3 P0 = Pp.xyz / Pp.w;
    C = vec3(0.0); dC = vec3(0.0); w0 = 0.0;
    for (int a = 0; a <= SV_NURBS_MAX_DEGREE; ++a) {
        if (a > deg) break;
        int idx = (span - deg + a) * stride;
        vec4 Pw = sv_table_texel(sv_nurbs_cps, near0 + idx);
        vec3 Q = Pw.xyz - Pw.w * P0;
        C += N[a] * Q; dC += D[a] * Q;
        w0 += N[a] * sv_table_texel(sv_nurbs_cps, pole0 + idx).w;
    }
}

// (t', rho) for a step that ends at meridian te beyond the pole `edge`; lo, hi: the period of t.
vec2 sv_nurbs_cross_pole(SvNurbsPatch P, int edge, float te, float lo, float hi) {
    int base = P.kv + P.nv + P.q + 1;  // after the V knots
    if ((edge - 2 * (edge / 2)) == 1 && (P.poles & (16 << (edge - 1))) != 0) base += SV_NURBS_POLE_TABLE + 4;
    float span = hi - lo;
    vec3 n = vec3(sv_nurbs_knot(base, 0), sv_nurbs_knot(base, 1), sv_nurbs_knot(base, 2));
    float t = lo + mod(te - lo, span);
    float f = (t - lo) / span * float(SV_NURBS_POLE_TABLE);
    int k = min(int(floor(f)), SV_NURBS_POLE_TABLE - 1);
    f = f - float(k);
    float dk = sv_nurbs_knot(base, 3 + k);
    float dk1 = sv_nurbs_knot(base, 4 + k);
    float t0 = t + (dk + f * (dk1 - dk));
    t0 = clamp(lo + mod(t0 - lo, span), lo, hi);
    vec3 a; vec3 da; float wa; vec3 b; vec3 db; float wb;
    sv_nurbs_pole_curve(P, edge, t, a, da, wa);
    sv_nurbs_pole_curve(P, edge, t0, b, db, wb);
    vec3 ap = a - dot(a, n) * n;
    vec3 bp = b - dot(b, n) * n;
    float bb = dot(bp, bp);
    float omega = dot(cross(b, db), n);  // d(angle of C)/dt at t0, times |C_perp|^2
    float h = span / float(SV_NURBS_POLE_TABLE);
    float phi = atan(dot(cross(-a, b), n), -(dot(a, b) - dot(a, n) * dot(b, n)));  // from -C(t) to C(t0)
    float delta = omega > 0.0 ? clamp(phi * bb / omega, -h, h) : 0.0;
    float na = length(ap);
    float nb = sqrt(bb);
    float rho = nb * wa > 0.0 ? na * wb / (nb * wa) : 1.0;
    float tp = t0 - delta;
    return vec2(clamp(lo + mod(tp - lo, span), lo, hi), rho);
}
