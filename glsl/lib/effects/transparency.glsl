// A translucent surface over opaque meshes: the colour's alpha is sv_opacity (VTK's translucent pass
// blends it; the actor's opacity routes it there, see splinevis.gl.inject).
uniform float sv_opacity;
