// Depth output: the red channel carries the window depth written to gl_FragDepth (analysis passes).
// The depth itself is computed by lib/core/raycast.glsl; this file only marks the effect as declared.
const int SV_DEPTH_OUTPUT_CHANNEL = 0;
