"""The Style object: which effects a scene declares, as data.

A :class:`Style` decides two things, kept apart on purpose:

* **code** -- which effect files are compiled into a program (:meth:`Style.effect_set`, :meth:`Style.defines`,
  :meth:`Style.include_files`). This is part of the program cache key: two styles with the same effect
  set share one compiled program.
* **parameters** -- colours, light directions, stripe frequencies, colormap ranges (:meth:`Style.uniforms`).
  They are uniforms; changing them never recompiles.

Effects (each lives in ``glsl/lib/effects/<name>.glsl`` and is compiled in only when declared):

============== ===================================================================================
lights          number of directional lights, 0..4 (0 = unlit base colour); diffuse Lambert terms
specular        Phong specular term on every light
colormap        base colour from the surface scalar (height for terrains) through a matplotlib colormap
texture         base colour from an RGB(A) image draped by the surface's (u, v)
environment     reflection of a latitude-longitude environment image
reflection_lines  stripes of a family of parallel light lines seen in the mirrored view ray (zebra)
highlight_lines   bands where the surface normal line meets one of a family of linear lights (view-independent)
isophotes       stripes of constant ``dot(n, L)``
antialias       the stripes above averaged over each pixel's footprint, the specular lobe widened by the
                spread of the normals over it (on by default whenever a stripe effect or specular is
                declared; ``antialias=False`` gives one sample's shading)
transparency    ``opacity < 1``: alpha output, composited by VTK's translucent pass
normals         output colour = encoded unit normal ``0.5 * (n + 1)`` (replaces shading)
curvature       output colour = a curvature (mean, Gaussian, principal) through a diverging colormap
draft           output colour = draft angle against a pull direction (green / yellow / red)
depth           output colour = window depth in the red channel (replaces shading)
============== ===================================================================================

``normals``, ``curvature``, ``draft`` and ``depth`` are output modes: at most one of them may be declared.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from ._validation import as_float64_array, check_choice

__all__ = ["Style", "EFFECTS", "OUTPUT_MODES", "MAX_LIGHTS", "CURVATURE_KINDS", "STRIPE_EFFECTS", "line_frame"]

MAX_LIGHTS = 4
OUTPUT_MODES = ("normals", "curvature", "draft", "depth")
#: What ``output="curvature"`` shows (``Style.curvature``), as the GLSL's sv_curvature_kind.
CURVATURE_KINDS = {"mean": 0, "gaussian": 1, "k1": 2, "k2": 3, "max": 4}
#: effect name -> (GLSL flag, include file). 'lights' and 'specular' share the lighting file.
EFFECTS: dict[str, tuple[str, str]] = {
    "lights": ("SV_NUM_LIGHTS", "lib/effects/lights.glsl"),
    "specular": ("SV_SPECULAR", "lib/effects/lights.glsl"),
    "colormap": ("SV_COLORMAP", "lib/effects/colormap.glsl"),
    "texture": ("SV_TEXTURE", "lib/effects/texture.glsl"),
    "environment": ("SV_ENVIRONMENT", "lib/effects/environment.glsl"),
    "reflection_lines": ("SV_REFLECTION_LINES", "lib/effects/reflection_lines.glsl"),
    "highlight_lines": ("SV_HIGHLIGHT_LINES", "lib/effects/highlight_lines.glsl"),
    "isophotes": ("SV_ISOPHOTES", "lib/effects/isophotes.glsl"),
    "antialias": ("SV_ANTIALIAS", "lib/effects/footprint.glsl"),
    "transparency": ("SV_TRANSPARENCY", "lib/effects/transparency.glsl"),
    "normals": ("SV_OUT_NORMALS", "lib/effects/normals.glsl"),
    "curvature": ("SV_OUT_CURVATURE", "lib/effects/curvature.glsl"),
    "draft": ("SV_OUT_DRAFT", "lib/effects/draft.glsl"),
    "depth": ("SV_OUT_DEPTH", "lib/effects/depth.glsl"),
}

#: The effects drawn as light/dark stripes of a smooth quantity (``glsl/lib/effects/footprint.glsl``), which
#: ``Style.antialias`` filters over the pixel.
STRIPE_EFFECTS = ("reflection_lines", "highlight_lines", "isophotes")

# Default light rig: a headlight slightly above-left and a weaker fill, given in camera coordinates
# (x right, y up, z towards the viewer) as directions *towards* the light.
_DEFAULT_LIGHTS = ((-0.3, 0.5, 1.0), (0.6, -0.2, 0.8), (0.0, 1.0, 0.2), (-1.0, 0.0, 0.3))


def _rgb(value, name):
    if isinstance(value, str):
        from matplotlib.colors import to_rgb

        try:
            return tuple(float(c) for c in to_rgb(value))
        except ValueError:
            raise ValueError(f"{name} {value!r} is not a colour name matplotlib knows (e.g. 'tan', '#c0a080').") from None
    arr = as_float64_array(value, name, ndim=1, shape_tail=(3,))
    if arr.min() < 0 or arr.max() > 1:
        raise ValueError(f"{name} must have RGB components in [0, 1], got {tuple(arr)}.")
    return tuple(float(c) for c in arr)


def _unit(value, name):
    v = as_float64_array(value, name, ndim=1, shape_tail=(3,))
    size = float(np.linalg.norm(v))
    if size == 0:
        raise ValueError(f"{name} must be a non-zero direction, got {tuple(v)}.")
    return tuple(float(c) for c in v / size)


def line_frame(axis) -> tuple:
    """``(b, c)``: unit vectors with ``(axis, b, c)`` right-handed orthonormal; ``c`` leans towards +z (towards
    +y for an axis along z). For the x axis ``b = y``, ``c = z``.

    >>> line_frame((1, 0, 0))
    ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    >>> line_frame((0, 0, 1))
    ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0))
    """
    a = np.asarray(_unit(axis, "axis"))
    up = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    c = up - np.dot(up, a) * a
    c /= np.linalg.norm(c)
    b = np.cross(c, a)
    return tuple(float(v) + 0.0 for v in b), tuple(float(v) + 0.0 for v in c)


@dataclass(frozen=True)
class Style:
    """How a spline actor is shaded; only the declared effects are compiled in.

    Parameters
    ----------
    lights : int, default 1
        Number of directional lights (0..4), fixed relative to the camera.
    specular : bool, default False
        Add a Phong specular term (needs ``lights >= 1``).
    color : str or (3,) float, default "tan"
        Base colour when neither ``colormap`` nor ``texture`` is declared.
    colormap : str, optional
        Name of a matplotlib colormap: colour by the surface scalar (height for terrains).
    scalar_range : (float, float), optional
        Scalar values mapped to the ends of the colormap; defaults to the model's range.
    texture : (H, W, 3|4) uint8 ndarray, optional
        Image draped over the surface's parameter domain (u, v in [0, 1]; for a terrain, its grid
        extent), row 0 at the top (north).
    texture_extent : (xmin, xmax, ymin, ymax), optional
        Geo-reference of ``texture`` in the model's coordinates (e.g. the image's own UTM extent); the
        surface outside it keeps its base colour. Default: the image covers the model's extent.
    environment : (H, W, 3) uint8 ndarray, optional
        Latitude-longitude environment image, reflected by the surface.
    reflection_lines : int, optional
        Number of parallel light lines (reflection-line stripes) over a half turn about their axis.
    reflection_axis : (3,) float, default (1, 0, 0)
        Direction of the light lines (world frame).
    highlight_lines : float, optional
        Spacing (world units) of linear lights for highlight lines [BeierChen1994].
    highlight_axis : (3,) float, default (1, 0, 0)
        Direction of the linear lights.
    highlight_plane : (3,) float, default (0, 0, 1)
        Normal of the plane that holds the lights (``highlight_axis`` must lie in it).
    highlight_height : float, optional
        The plane's offset along ``highlight_plane`` (world); default: above the model by its size.
    isophotes : int, optional
        Number of isophote bands of ``dot(n, L)`` for the first light direction.
    antialias : bool, default True
        Average the stripes of reflection lines, highlight lines and isophotes over each pixel's footprint
        (from the screen-space derivatives of the stripe coordinate; ``glsl/lib/effects/footprint.glsl``): a
        stripe narrower than a pixel fades to its mean instead of aliasing into a moire; and widen the
        specular highlight by the spread of the normals over the pixel [Toksvig2005], so a highlight narrower
        than a pixel does not sparkle. False draws the plain step and the one-normal highlight. Compiled in
        only with a stripe effect or specular.
    output : {"normals", "curvature", "draft", "depth"}, optional
        Replace shading by an analysis output.
    curvature : {"mean", "gaussian", "k1", "k2", "max"}, default "mean"
        What ``output="curvature"`` shows: mean, Gaussian, maximum / minimum principal curvature, or the
        principal curvature of larger magnitude (a uniform).
    pull_direction : (3,) float, default (0, 0, 1)
        Mould pull direction for ``output="draft"``.
    draft_angle : float, default 1.0
        Smallest acceptable draft in degrees (``output="draft"``).
    ambient, diffuse, specular_power : float
        Lighting parameters (uniforms; changing them does not recompile).
    curvature_scale : float, default 1.0
        Curvature shown at full colour by ``output="curvature"`` (a uniform).
    opacity : float in (0, 1], default 1.0
        Below 1 the surface is drawn translucent over opaque meshes (effect ``transparency``: the alpha
        output is compiled in and VTK's translucent pass composites it). Every sheet a ray crosses is
        composited (for an isosurface: one per cube the ray crosses), so back sheets show through.

    Examples
    --------
    >>> from splinevis import Style
    >>> s = Style(lights=2, specular=True, reflection_lines=12)
    >>> sorted(s.effect_set())
    ['antialias', 'lights', 'reflection_lines', 'specular']
    >>> Style(lights=2).effect_set() == Style(lights=2, color="red").effect_set()
    True
    """

    lights: int = 1
    specular: bool = False
    color: Any = "tan"
    colormap: str | None = None
    scalar_range: tuple | None = None
    texture: Any = field(default=None, compare=False, hash=False)
    texture_extent: tuple | None = None
    environment: Any = field(default=None, compare=False, hash=False)
    reflection_lines: int | None = None
    reflection_axis: tuple = (1.0, 0.0, 0.0)
    highlight_lines: float | None = None
    highlight_axis: tuple = (1.0, 0.0, 0.0)
    highlight_plane: tuple = (0.0, 0.0, 1.0)
    highlight_height: float | None = None
    isophotes: int | None = None
    antialias: bool = True
    output: str | None = None
    curvature: str = "mean"
    pull_direction: tuple = (0.0, 0.0, 1.0)
    draft_angle: float = 1.0
    ambient: float = 0.15
    diffuse: float = 0.85
    specular_power: float = 40.0
    curvature_scale: float = 1.0
    opacity: float = 1.0

    def __post_init__(self):
        if isinstance(self.lights, bool) or not isinstance(self.lights, (int, np.integer)) or not 0 <= self.lights <= MAX_LIGHTS:
            raise ValueError(f"Style.lights must be an integer in 0..{MAX_LIGHTS}, got {self.lights!r}.")
        if self.specular and self.lights == 0:
            raise ValueError("Style.specular=True needs at least one light; set lights >= 1.")
        object.__setattr__(self, "color", _rgb(self.color, "Style.color"))
        if self.colormap is not None:
            import matplotlib

            if self.colormap not in matplotlib.colormaps:
                raise ValueError(f"Style.colormap {self.colormap!r} is not a matplotlib colormap (e.g. 'viridis', 'terrain').")
        if self.colormap is not None and self.texture is not None:
            raise ValueError("Style: declare either colormap or texture as the base colour, not both.")
        if self.scalar_range is not None:
            lo, hi = as_float64_array(self.scalar_range, "Style.scalar_range", ndim=1, shape_tail=(2,))
            if not hi > lo:
                raise ValueError(f"Style.scalar_range must be (low, high) with low < high, got {self.scalar_range!r}.")
        if self.texture_extent is not None:
            if self.texture is None:
                raise ValueError("Style.texture_extent needs a texture to geo-reference.")
            ext = as_float64_array(self.texture_extent, "Style.texture_extent", ndim=1, shape_tail=(4,))
            if not (ext[1] > ext[0] and ext[3] > ext[2]):
                raise ValueError(f"Style.texture_extent must be (xmin, xmax, ymin, ymax) with min < max, got {tuple(ext)}.")
        for name in ("texture", "environment"):
            img = getattr(self, name)
            if img is not None:
                arr = np.asarray(img)
                if arr.ndim != 3 or arr.shape[2] not in (3, 4) or arr.dtype != np.uint8:
                    raise ValueError(f"Style.{name} must be an (H, W, 3 or 4) uint8 image, got {arr.dtype} {arr.shape}.")
        for name in ("reflection_lines", "isophotes"):
            v = getattr(self, name)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1):
                raise ValueError(f"Style.{name} must be a positive integer count of stripes, got {v!r}.")
        if not isinstance(self.antialias, (bool, np.bool_)):
            raise ValueError(f"Style.antialias must be True or False, got {self.antialias!r}.")
        if self.isophotes is not None and self.lights == 0:
            raise ValueError("Style.isophotes are bands of dot(n, L) for the first light: set lights >= 1.")
        if self.output is not None:
            check_choice(self.output, "Style.output", OUTPUT_MODES)
        check_choice(self.curvature, "Style.curvature", tuple(CURVATURE_KINDS))
        for name in ("reflection_axis", "highlight_axis", "highlight_plane", "pull_direction"):
            object.__setattr__(self, name, _unit(getattr(self, name), f"Style.{name}"))
        if abs(float(np.dot(self.highlight_axis, self.highlight_plane))) > 1e-9:
            raise ValueError(f"Style.highlight_axis {self.highlight_axis} must lie in the plane of lights (be "
                             f"perpendicular to Style.highlight_plane {self.highlight_plane}).")
        if self.highlight_lines is not None and not (np.isfinite(self.highlight_lines) and self.highlight_lines > 0):
            raise ValueError(f"Style.highlight_lines is the spacing of the lights, a number > 0; got {self.highlight_lines!r}.")
        if not (np.isfinite(self.draft_angle) and 0 <= self.draft_angle < 90):
            raise ValueError(f"Style.draft_angle must be degrees in [0, 90), got {self.draft_angle!r}.")
        if isinstance(self.opacity, bool) or not isinstance(self.opacity, (int, float, np.floating)) or not 0 < self.opacity <= 1:
            raise ValueError(f"Style.opacity must be a number in (0, 1], got {self.opacity!r}.")

    # -- code -----------------------------------------------------------------------------------------
    def effect_set(self) -> frozenset:
        """The names of the declared effects: what decides the compiled code.

        An output mode (normals, curvature, depth) replaces shading, so lights, colours and overlays
        are not compiled in with it.

        Examples
        --------
        >>> sorted(Style(lights=2, opacity=0.5).effect_set())
        ['lights', 'transparency']
        >>> sorted(Style(reflection_lines=8).effect_set()), sorted(Style(reflection_lines=8, antialias=False).effect_set())
        (['antialias', 'lights', 'reflection_lines'], ['lights', 'reflection_lines'])
        >>> Style(lights=2, reflection_lines=12, output="normals").effect_set()
        frozenset({'normals'})
        """
        if self.output is not None:
            return frozenset({self.output})
        on = set()
        if self.lights:
            on.add("lights")
        if self.specular:
            on.add("specular")
        if self.colormap is not None:
            on.add("colormap")
        for name in ("texture", "environment", "reflection_lines", "highlight_lines", "isophotes"):
            if getattr(self, name) is not None:
                on.add(name)
        if self.opacity < 1:
            on.add("transparency")
        if self.antialias and (on.intersection(STRIPE_EFFECTS) or "specular" in on):
            on.add("antialias")
        return frozenset(on)

    def defines(self) -> dict:
        """Compile-time flags for the declared effects (``SV_NUM_LIGHTS`` carries the count).

        Examples
        --------
        >>> sorted(Style(lights=2, specular=True).defines().items())
        [('SV_ANTIALIAS', True), ('SV_NUM_LIGHTS', 2), ('SV_SPECULAR', True)]
        """
        out = {}
        for name in self.effect_set():
            flag = EFFECTS[name][0]
            out[flag] = self.lights if name == "lights" else True
        return out

    def include_files(self) -> list[str]:
        """The effect files to include, without duplicates, in a stable order.

        Examples
        --------
        >>> Style(lights=2, specular=True, reflection_lines=12).include_files()
        ['lib/effects/lights.glsl', 'lib/effects/reflection_lines.glsl', 'lib/effects/footprint.glsl']
        """
        files = []
        for name in EFFECTS:
            if name in self.effect_set() and EFFECTS[name][1] not in files:
                files.append(EFFECTS[name][1])
        return files

    # -- parameters -----------------------------------------------------------------------------------
    def light_directions_camera(self) -> np.ndarray:
        """(lights, 3) unit directions towards each light in camera coordinates.

        Examples
        --------
        >>> d = Style(lights=2).light_directions_camera()
        >>> d.shape, np.linalg.norm(d, axis=1).round(12)
        ((2, 3), array([1., 1.]))
        """
        d = np.asarray(_DEFAULT_LIGHTS[: self.lights], dtype=np.float64).reshape(-1, 3)
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def uniforms(self) -> dict:
        """Scalar and vector uniforms (name -> float or tuple); set without recompiling (uniforms of
        effects that are not compiled in are simply not found by the driver and ignored).

        Examples
        --------
        >>> Style(lights=1, color=(1.0, 0.5, 0.0), reflection_lines=8).uniforms()
        {'sv_color': (1.0, 0.5, 0.0), 'sv_ambient': 0.15, 'sv_diffuse': 0.85, 'sv_stripes': 8.0, 'sv_line_b': (0.0, 1.0, 0.0), 'sv_line_c': (0.0, 0.0, 1.0)}
        """
        u = {"sv_color": self.color, "sv_ambient": float(self.ambient), "sv_diffuse": float(self.diffuse)}
        if self.specular:
            u["sv_specular_power"] = float(self.specular_power)
        if self.reflection_lines is not None:
            u["sv_stripes"] = float(self.reflection_lines)
            u["sv_line_b"], u["sv_line_c"] = line_frame(self.reflection_axis)
        if self.highlight_lines is not None:
            u["sv_highlight_plane"] = self.highlight_plane
            u["sv_highlight_across"] = tuple(float(v) for v in np.cross(self.highlight_plane, self.highlight_axis))
            u["sv_highlight_spacing"] = float(self.highlight_lines)
        if self.isophotes is not None:
            u["sv_isophote_bands"] = float(self.isophotes)
        if self.colormap is not None and self.scalar_range is not None:
            u["sv_scalar_range"] = tuple(float(v) for v in self.scalar_range)
        if self.output == "curvature":
            u["sv_curvature_scale"] = float(self.curvature_scale)
            u["sv_curvature_kind"] = CURVATURE_KINDS[self.curvature]
        if self.output == "draft":
            u["sv_pull_dir"] = self.pull_direction
            u["sv_draft_min"] = float(self.draft_angle)
        if self.opacity < 1:
            u["sv_opacity"] = float(self.opacity)
        return u

    def replace(self, **changes) -> "Style":
        """A copy with some fields changed (styles are immutable).

        Examples
        --------
        >>> s = Style(lights=2)
        >>> s.replace(lights=3, specular=True).lights, s.lights
        (3, 2)
        """
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        unknown = set(changes) - set(values)
        if unknown:
            raise TypeError(f"Style has no field(s) {sorted(unknown)}; fields are {sorted(values)}.")
        values.update(changes)
        return Style(**values)
