// Non-uniform rational B-spline patches evaluated from float tables, for the "surface" kind [Kanai2007, sec. 3.1].
//
// Tables (splinevis/nurbs/program.py):
//   sv_nurbs_header : 4 texels per patch. texel 0 = (p, q, nu, nv); texel 1 = knot offsets of U and V as
//                     (hi, lo, hi, lo) with offset = hi * 4096 + lo (each part exact in float32, so offsets up to
//                     2^36 stay exact); texel 2 = control-point offset (hi, lo), closed-in-u, closed-in-v;
//                     texel 3 = (patch magnitude M, largest |knot|) for the float32 tolerances, and the
//                     collapsed edges (poles) as bits 1: u=lo, 2: u=hi, 4: v=lo, 8: v=hi, and (16 << edge)
//                     where that pole has an antipode table (no half-turn symmetry: lib/nurbs/poles.glsl).
//   sv_nurbs_knots  : all knot vectors, one float each (read with sv_table_float); after a patch's V knots,
//                     its pole tables (lower edge first).
//   sv_nurbs_cps    : homogeneous control points (w (P - offset), w), one texel each, P[k, l] at k * nv + l.
// Loops run to the constant SV_NURBS_MAX_DEGREE and leave early at the patch's degree (no switch per degree).
// SV_NURBS_MAX_DEGREE is 7 unless the program defines it higher (splinevis/nurbs/program.py: the model's
// largest degree when above 7, up to splinevis.nurbs.basis.MAX_DEGREE): the local arrays are sized by it,
// so models of degree <= 7 keep the arrays (and registers) of the degree-7 program.
#include "lib/core/table.glsl"

#ifndef SV_NURBS_MAX_DEGREE
#define SV_NURBS_MAX_DEGREE 7
#endif
#define SV_NURBS_ORDER (SV_NURBS_MAX_DEGREE + 1)   // the row length of the flattened triangular tables

// (the samplers sv_nurbs_header, sv_nurbs_knots, sv_nurbs_cps are declared by VTK for the actor's textures)

struct SvNurbsPatch {
    int p; int q; int nu; int nv;
    int ku; int kv; int cp;
    bool closed_u; bool closed_v;
    float magnitude; float knot_max;
    int poles;
};

int sv_nurbs_int(vec2 hilo) {
    return int(hilo.x) * 4096 + int(hilo.y);
}

SvNurbsPatch sv_nurbs_patch(int id) {
    vec4 t0 = sv_table_texel(sv_nurbs_header, 4 * id);
    vec4 t1 = sv_table_texel(sv_nurbs_header, 4 * id + 1);
    vec4 t2 = sv_table_texel(sv_nurbs_header, 4 * id + 2);
    vec4 t3 = sv_table_texel(sv_nurbs_header, 4 * id + 3);
    SvNurbsPatch P;
    P.p = int(t0.x); P.q = int(t0.y); P.nu = int(t0.z); P.nv = int(t0.w);
    P.ku = sv_nurbs_int(t1.xy); P.kv = sv_nurbs_int(t1.zw); P.cp = sv_nurbs_int(t2.xy);
    P.closed_u = t2.z > 0.5; P.closed_v = t2.w > 0.5;
    P.magnitude = t3.x; P.knot_max = t3.y; P.poles = int(t3.z + 0.5);
    return P;
}

float sv_nurbs_knot(int offset, int k) {
    return sv_table_float(sv_nurbs_knots, offset + k);
}

// Span i with U[i] <= u < U[i+1], p <= i <= n - 1 for n control points (the last span at u = U[n])
// [PieglTiller1997, A2.1]: binary search, at most 32 halvings.
int sv_nurbs_find_span(int offset, int p, int n, float u) {
    if (u >= sv_nurbs_knot(offset, n)) {
        int i = n - 1;  // the last non-empty span
        for (int k = 0; k < 32; ++k) {
            if (i <= p || sv_nurbs_knot(offset, i) < sv_nurbs_knot(offset, i + 1)) break;
            --i;
        }
        return i;
    }
    int low = p;
    int high = n;
    for (int k = 0; k < 32; ++k) {
        if (high - low <= 1) break;
        int mid = (low + high) / 2;
        if (u < sv_nurbs_knot(offset, mid)) high = mid; else low = mid;
    }
    return low;
}

float sv_nurbs_div(float a, float b) {
    return b != 0.0 ? a / b : 0.0;
}

// Basis functions N and their first and second derivatives D1, D2 of the p + 1 functions that do not vanish
// on span `span` [PieglTiller1997, A2.2 and A2.3, with the derivative order fixed at 2].
void sv_nurbs_basis(int offset, int span, int p, float u, out float N[SV_NURBS_ORDER],
                    out float D1[SV_NURBS_ORDER], out float D2[SV_NURBS_ORDER]) {
    float ndu[SV_NURBS_ORDER * SV_NURBS_ORDER];
    float left[SV_NURBS_ORDER];
    float right[SV_NURBS_ORDER];
    for (int i = 0; i < SV_NURBS_ORDER; ++i) { N[i] = 0.0; D1[i] = 0.0; D2[i] = 0.0; left[i] = 0.0; right[i] = 0.0; }
    ndu[0] = 1.0;
    for (int j = 1; j <= SV_NURBS_MAX_DEGREE; ++j) {
        if (j > p) break;
        left[j] = u - sv_nurbs_knot(offset, span + 1 - j);
        right[j] = sv_nurbs_knot(offset, span + j) - u;
        float saved = 0.0;
        for (int r = 0; r < SV_NURBS_MAX_DEGREE; ++r) {
            if (r >= j) break;
            ndu[j * SV_NURBS_ORDER + r] = right[r + 1] + left[j - r];          // knot differences
            float temp = sv_nurbs_div(ndu[r * SV_NURBS_ORDER + j - 1], ndu[j * SV_NURBS_ORDER + r]);
            ndu[r * SV_NURBS_ORDER + j] = saved + right[r + 1] * temp;        // basis functions
            saved = left[j - r] * temp;
        }
        ndu[j * SV_NURBS_ORDER + j] = saved;
    }
    int pk1 = p - 1;
    int pk2 = p - 2;
    for (int r = 0; r <= SV_NURBS_MAX_DEGREE; ++r) {
        if (r > p) break;
        N[r] = ndu[r * SV_NURBS_ORDER + p];
        if (p < 1) continue;
        // first derivative (k = 1): a1 = (a1_0, a1_1)
        float a10 = 0.0; float a11 = 0.0; float d = 0.0;
        if (r >= 1) {
            a10 = sv_nurbs_div(1.0, ndu[(pk1 + 1) * SV_NURBS_ORDER + r - 1]);
            d = a10 * ndu[(r - 1) * SV_NURBS_ORDER + pk1];
        }
        if (r <= pk1) {
            a11 = sv_nurbs_div(-1.0, ndu[(pk1 + 1) * SV_NURBS_ORDER + r]);
            d += a11 * ndu[r * SV_NURBS_ORDER + pk1];
        }
        D1[r] = float(p) * d;
        if (p < 2) continue;
        // second derivative (k = 2)
        int rk = r - 2;
        d = 0.0;
        if (r >= 2) d = sv_nurbs_div(a10, ndu[(pk2 + 1) * SV_NURBS_ORDER + rk]) * ndu[rk * SV_NURBS_ORDER + pk2];
        int j1 = rk >= -1 ? 1 : -rk;
        int j2 = r - 1 <= pk2 ? 1 : p - r;
        for (int j = 1; j <= 2; ++j) {
            if (j < j1 || j > j2) continue;
            float aj = (j == 1 ? a11 - a10 : -a11);  // a1_j - a1_{j-1}, a1_2 = 0
            d += sv_nurbs_div(aj, ndu[(pk2 + 1) * SV_NURBS_ORDER + rk + j]) * ndu[(rk + j) * SV_NURBS_ORDER + pk2];
        }
        if (r <= pk2) d += sv_nurbs_div(-a11, ndu[(pk2 + 1) * SV_NURBS_ORDER + r]) * ndu[r * SV_NURBS_ORDER + pk2];
        D2[r] = float(p * (p - 1)) * d;
    }
}

// The rational surface point and its derivatives S, S_u, S_v, S_uu, S_uv, S_vv at (u, v) of one patch
// (model coordinates): homogeneous sums A^(k,l) = sum N_a^(k) N_b^(l) Pw_ab, then the quotient rule
// [PieglTiller1997, A3.6 and A4.4].
void sv_nurbs_surface(SvNurbsPatch P, vec2 uv, out vec3 S, out vec3 Su, out vec3 Sv, out vec3 Suu,
                      out vec3 Suv, out vec3 Svv) {
    int su = sv_nurbs_find_span(P.ku, P.p, P.nu, uv.x);
    int sv = sv_nurbs_find_span(P.kv, P.q, P.nv, uv.y);
    float Nu[SV_NURBS_ORDER]; float Du[SV_NURBS_ORDER]; float DDu[SV_NURBS_ORDER];
    float Nv[SV_NURBS_ORDER]; float Dv[SV_NURBS_ORDER]; float DDv[SV_NURBS_ORDER];
    sv_nurbs_basis(P.ku, su, P.p, uv.x, Nu, Du, DDu);
    sv_nurbs_basis(P.kv, sv, P.q, uv.y, Nv, Dv, DDv);
    vec4 A00 = vec4(0.0); vec4 A10 = vec4(0.0); vec4 A01 = vec4(0.0);
    vec4 A20 = vec4(0.0); vec4 A11 = vec4(0.0); vec4 A02 = vec4(0.0);
    for (int a = 0; a <= SV_NURBS_MAX_DEGREE; ++a) {
        if (a > P.p) break;
        int row = P.cp + (su - P.p + a) * P.nv + (sv - P.q);
        vec4 c0 = vec4(0.0); vec4 c1 = vec4(0.0); vec4 c2 = vec4(0.0);  // sums over b with N_b, N_b', N_b''
        for (int b = 0; b <= SV_NURBS_MAX_DEGREE; ++b) {
            if (b > P.q) break;
            vec4 Pw = sv_table_texel(sv_nurbs_cps, row + b);
            c0 += Nv[b] * Pw; c1 += Dv[b] * Pw; c2 += DDv[b] * Pw;
        }
        A00 += Nu[a] * c0; A01 += Nu[a] * c1; A02 += Nu[a] * c2;
        A10 += Du[a] * c0; A11 += Du[a] * c1;
        A20 += DDu[a] * c0;
    }
    float w = A00.w;
    S = A00.xyz / w;
    Su = (A10.xyz - A10.w * S) / w;
    Sv = (A01.xyz - A01.w * S) / w;
    Suu = (A20.xyz - 2.0 * A10.w * Su - A20.w * S) / w;
    Suv = (A11.xyz - A10.w * Sv - A01.w * Su - A11.w * S) / w;
    Svv = (A02.xyz - 2.0 * A01.w * Sv - A02.w * S) / w;
}
