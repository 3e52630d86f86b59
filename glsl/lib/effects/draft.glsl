// Draft angle against a pull direction d (mould release): the angle between the surface and d,
// alpha = asin(n . d) in degrees, with the surface's own orientation n (not turned to the viewer).
// alpha >= sv_draft_min: green (releases), alpha <= -sv_draft_min: red (undercut), in between: yellow
// (too little draft); brighter with |alpha| up to 45 degrees.
uniform vec3 sv_pull_dir;    // unit
uniform float sv_draft_min;  // degrees

vec3 sv_draft_color(vec3 n) {
    float a = degrees(asin(clamp(dot(normalize(n), sv_pull_dir), -1.0, 1.0)));
    float strength = 0.45 + 0.55 * clamp(abs(a) / 45.0, 0.0, 1.0);
    if (a >= sv_draft_min) return vec3(0.1, 0.75, 0.2) * strength;
    if (a <= -sv_draft_min) return vec3(0.85, 0.1, 0.1) * strength;
    return vec3(0.95, 0.85, 0.1);
}
