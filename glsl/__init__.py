"""GLSL sources of splinevis (the top-level glsl/ folder of the repository)."""
