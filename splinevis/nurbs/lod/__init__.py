"""Large NURBS models as meshes with proven deviation bounds and crack-free levels of detail [Kumar1997].

The data flows one way (each module knows only the ones before it):

* ``bezier``    -- every surface of a model cut into rational Bezier patches by knot insertion, vectorized by
  degree; each patch keeps its parent surface, its rectangle of the parent's domain and the parent's trims;
* ``adjacency`` -- which patch sides share a boundary (tolerance from the model size): the unique edges;
* ``bounds``    -- proven bounds of the distance between a patch and a triangle through three of its points
  (derivative bounds of the Bezier form) and between a boundary curve and its chords;
* ``adaptive``  -- the adaptive tessellation of one patch to a bound ``delta`` with its boundary chains given,
  so that neighbours which are given the same chains share them exactly (no cracks);
* later: super-surfaces (pseudo-Gauss-map spans), levels of detail, view-dependent selection, the threaded
  pipeline and the walkthrough.
"""
