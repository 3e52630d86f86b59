// Per-fragment work counters of the debug build (compiled only when SV_DEBUG_COUNTERS is defined: the
// terrain program's option debug="counters"; read back by splinevis.analysis.profile.fragment_counters).
//
// The program's loops add to these globals; the fragment then writes, instead of its colour, ONE of them,
// chosen by the uniform sv_counter_select, as a 24-bit integer in the colour channels (R = bits 16..23,
// G = bits 8..15, B = bits 0..7, alpha 1: an opaque fragment is stored as written, so every count reads
// back exactly from an 8-bit framebuffer). A frame per counter; changing the uniform never recompiles.
//   0  flags: 1 (the fragment ran) + 2 (it hit: shading ran)
//   1  traversal steps: iterations of the hierarchy walk (blocks visited at any level, cells included)
//   2  cells tested: level-0 cells whose two triangles were intersected (coefficients loaded)
//   3  root-finder calls: restricted polynomials handed to sv_first_root
//   4  root-finder steps: Newton / bracketed-Newton steps summed over those calls
int sv_count_traversal = 0;
int sv_count_cells = 0;
int sv_count_root_calls = 0;
int sv_count_root_steps = 0;
uniform int sv_counter_select;

vec4 sv_counters_color(bool hit) {
    int v = 1 + (hit ? 2 : 0);
    if (sv_counter_select == 1) v = sv_count_traversal;
    if (sv_counter_select == 2) v = sv_count_cells;
    if (sv_counter_select == 3) v = sv_count_root_calls;
    if (sv_counter_select == 4) v = sv_count_root_steps;
    v = clamp(v, 0, 16777215);
    return vec4(float(v / 65536), float((v / 256) % 256), float(v % 256), 255.0) / 255.0;
}
