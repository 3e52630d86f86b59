"""Smooth geometry images [Losasso2003]: a closed genus-0 triangle mesh as one bicubic B-spline on an
octahedral domain. This stage: checking that an input mesh can be parametrized on the sphere
(:mod:`.validate`)."""
