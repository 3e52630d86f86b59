// Shading filtered over the pixel's footprint (Style.antialias): which quad neighbours' derivatives hold,
// and the stripe filter. The light/dark step shared by reflection lines, isophotes and highlight lines, as a function of a smooth
// stripe coordinate x: one dark/bright pair per unit, dark where fract(x) < 1/2 [the float64 twin:
// splinevis.analysis.footprint.stripe_bright].
// With SV_ANTIALIAS the step is averaged over the pixel's footprint, a box of width w (in units of x) along x:
// w = |dx/dX| + |dx/dY| from the screen-space derivatives (what fwidth gives), the support of the distribution
// of a linear x over a square pixel. The average is the difference of the step's antiderivative
//   B(x) = floor(x) / 2 + max(fract(x) - 1/2, 0)
// at the box's ends, divided by w: a stripe narrower than the pixel fades to its mean 1/2 instead of aliasing
// (a moire), and a pixel that straddles an edge gets the share of each colour it covers.
// The box is placed on fract(x), in [0, 1): B's floor term stays small and float32 keeps it exact.
// Below SV_STRIPE_MIN_WIDTH (a thousandth of a stripe) the plain step is used: the average differs from it only
// in pixels whose centre lies within w/2 of an edge. Above it the float32 rounding of the average is at most
// about (4 / w + 6) u (u = 2^-24: the ends' rounding, twice, over w, plus the division), 2.5e-4 at the
// smallest w, below a 1/255 grey level. A footprint that is not finite (a derivative across a silhouette) or
// beyond SV_STRIPE_MAX_WIDTH stripes gives the mean.
const float SV_STRIPE_MIN_WIDTH = 1.0 / 1024.0;
const float SV_STRIPE_MAX_WIDTH = 1048576.0;

float sv_stripe_integral(float x) {
    return 0.5 * floor(x) + max(fract(x) - 0.5, 0.0);
}

// Share of bright (0 dark .. 1 bright) of the stripe coordinate x over a footprint of width w.
float sv_stripe_bright(float x, float w) {
#ifdef SV_ANTIALIAS
    if (!(w < SV_STRIPE_MAX_WIDTH)) return 0.5;
    if (w >= SV_STRIPE_MIN_WIDTH) {
        float xr = fract(x);
        return (sv_stripe_integral(xr + 0.5 * w) - sv_stripe_integral(xr - 0.5 * w)) / w;
    }
#endif
    return fract(x) < 0.5 ? 0.0 : 1.0;
}

// 1 where this fragment's surface hit is real. A ray-cast program shades a miss too before discarding it when
// SV_ANTIALIAS is on (splinevis/gl/inject.py), because derivatives are differences across the 2 x 2 pixel
// quad: a neighbour that missed (outside the surface, or outside the proxy primitive drawn) holds no stripe
// coordinate, and its difference would be noise (grey dots along the proxy's edges). A nonzero derivative of
// this flag marks that neighbour; the footprint is then taken from the other direction alone (twice it, the
// same estimate for a square pixel), or, with no valid neighbour at all, no filtering.
float sv_footprint_valid = 1.0;

// Footprint width from the stripe coordinate's screen-space rates ax = |dx/dX| and ay = |dx/dY|.
float sv_stripe_footprint(float ax, float ay) {
    bool bad_x = dFdx(sv_footprint_valid) != 0.0;
    bool bad_y = dFdy(sv_footprint_valid) != 0.0;
    if (bad_x && bad_y) return 0.0;
    if (bad_x) return 2.0 * ay;
    if (bad_y) return 2.0 * ax;
    return ax + ay;
}

// The footprint width of a stripe coordinate x: |dx/dX| + |dx/dY| (0 without SV_ANTIALIAS: the plain step).
#ifdef SV_ANTIALIAS
#define sv_stripe_width(x) sv_stripe_footprint(abs(dFdx(x)), abs(dFdy(x)))
#else
#define sv_stripe_width(x) 0.0
#endif
