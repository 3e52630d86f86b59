"""Analytic test surfaces with exact float64 ray casters (the foundation's first spline actor)."""

from .patch import QuarticTrianglePatch

__all__ = ["QuarticTrianglePatch"]
