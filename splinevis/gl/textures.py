"""RGBA32F textures on both sides: moderngl textures for the pass runner (:mod:`splinevis.gl.passes`) and
VTK textures for the spline programs' tables, from the same float32 ``(H, W, 4)`` arrays.

An array ``a`` of shape ``(H, W, 4)`` is a texture of width ``W`` and height ``H``; ``a[j, i]`` is the texel
``ivec2(i, j)``. :func:`to_vtk_image` and :func:`to_vtk_texture` share a C-contiguous float32 array with VTK
instead of copying it (the tables of a large volume exist once in memory).
"""

from __future__ import annotations

import numpy as np

from .context import current, max_texture_size

__all__ = ["as_rgba32f", "upload_rgba32f", "empty_rgba32f", "read_rgba32f", "to_vtk_image", "to_vtk_texture"]


# --------------------------------------------------------------------------------------------------
def as_rgba32f(values, name: str = "values") -> np.ndarray:
    """``values`` as a C-contiguous float32 ``(H, W, 4)`` array, the layout of an RGBA32F texture.

    Parameters
    ----------
    values : (H, W) or (H, W, C) array_like, C in 1..4
        Missing channels are filled with zeros. Returned as is (no copy) when already float32
        ``(H, W, 4)`` and C-contiguous.
    name : str
        Used in error messages.

    Returns
    -------
    (H, W, 4) float32 ndarray

    Examples
    --------
    >>> t = as_rgba32f(np.arange(6.0).reshape(2, 3))
    >>> t.shape, t.dtype, t[..., 0].tolist(), float(abs(t[..., 1:]).max())
    ((2, 3, 4), dtype('float32'), [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]], 0.0)
    >>> as_rgba32f(t) is t  # already an RGBA32F layout: no copy
    True
    """
    a = _as_hwc(values, name)
    if a.shape[2] == 4:
        return np.ascontiguousarray(a, dtype=np.float32)
    out = np.zeros(a.shape[:2] + (4,), dtype=np.float32)
    out[:, :, :a.shape[2]] = a
    return out


def _as_hwc(values, name: str) -> np.ndarray:
    """``values`` as an ``(H, W, C)`` array (a view when possible), C in 1..4."""
    a = np.asarray(values)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or not 1 <= a.shape[2] <= 4 or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"{name} must have shape (H, W) or (H, W, C) with H, W >= 1 and C in 1..4; "
                         f"got {np.shape(values)}.")
    return a


def _check_size(shape, what: str) -> None:
    limit = max_texture_size()
    if max(shape) > limit:
        raise ValueError(
            f"{what} has shape {tuple(shape)} (rows, columns), but this OpenGL implementation's "
            f"GL_MAX_TEXTURE_SIZE is {limit}: split it into tiles of at most {limit} x {limit}, "
            "or use a CPU path."
        )


def upload_rgba32f(values, name: str = "values"):
    """A new RGBA32F texture holding ``values`` (see :func:`as_rgba32f`), with nearest filtering.

    The caller owns the texture (release it inside :func:`splinevis.gl.context.current`).

    Returns
    -------
    moderngl.Texture

    Examples
    --------
    >>> values = np.random.default_rng(0).random((2, 3, 4), dtype=np.float32)
    >>> texture = upload_rgba32f(values)
    >>> texture.size, bool((read_rgba32f(texture) == values).all())  # (width, height); exact round trip
    ((3, 2), True)
    >>> with current():
    ...     texture.release()
    """
    data = as_rgba32f(values, name)
    _check_size(data.shape[:2], name)
    with current() as ctx:
        tex = ctx.texture((data.shape[1], data.shape[0]), 4, data, dtype="f4")
        tex.filter = (ctx.NEAREST, ctx.NEAREST)
        return tex


def empty_rgba32f(shape):
    """A new, uninitialised RGBA32F texture of ``shape = (H, W)``, with nearest filtering.

    Returns
    -------
    moderngl.Texture

    Examples
    --------
    >>> texture = empty_rgba32f((2, 3))
    >>> texture.size, texture.components, texture.dtype
    ((3, 2), 4, 'f4')
    >>> with current():
    ...     texture.release()
    """
    _check_size(shape, "texture")
    with current() as ctx:
        tex = ctx.texture((int(shape[1]), int(shape[0])), 4, dtype="f4")
        tex.filter = (ctx.NEAREST, ctx.NEAREST)
        return tex


def read_rgba32f(texture) -> np.ndarray:
    """Read an RGBA32F texture back as a float32 ``(H, W, 4)`` array: exact, no conversion.

    Returns
    -------
    (H, W, 4) float32 ndarray

    Examples
    --------
    >>> texture = upload_rgba32f(np.full((1, 2), 0.1))  # one channel given, the others zero
    >>> read_rgba32f(texture)
    array([[[0.1, 0. , 0. , 0. ],
            [0.1, 0. , 0. , 0. ]]], dtype=float32)
    >>> with current():
    ...     texture.release()
    """
    w, h = texture.size
    out = np.empty((h, w, 4), dtype=np.float32)
    with current() as ctx:
        _alive(texture, ctx, "texture").read_into(out)
    return out


def _alive(texture, ctx, what: str):
    """``texture`` if it belongs to the live context; its GL name means nothing in another one."""
    if texture.ctx is not ctx:
        raise ValueError(
            f"{what} is a texture of an OpenGL context that no longer exists: creating or finalizing a VTK "
            "EGL render window destroys the context it shares the EGL display with. Keep results that must "
            "outlive VTK rendering as arrays (readback=True) and upload them again."
        )
    return texture


# --------------------------------------------------------------------------------------------------
def to_vtk_image(values, *, spacing=(1.0, 1.0), origin=(0.0, 0.0), name: str = "values"):
    """Wrap a float32 ``(H, W, C)`` (or ``(H, W)``) array as the point scalars of a ``vtkImageData``.

    The image has dimensions ``(W, H, 1)``; point ``i + j * W`` (x fastest, VTK's order) is
    ``values[j, i]``, so row ``j`` of the array lies at ``y = origin[1] + j * spacing[1]``.

    A C-contiguous float32 array is shared, not copied: writes to it show in VTK and the other way
    round. VTK keeps the array alive for as long as its data array exists (the array is held by an
    observer of the VTK array's deletion), so the caller may drop its own reference. Other dtypes or
    layouts are converted to a float32 copy first.

    Parameters
    ----------
    values : (H, W) or (H, W, C) array_like, C in 1..4
    spacing, origin : (x, y) floats
    name : str
        Name of the point-data array.

    Returns
    -------
    vtkImageData

    Examples
    --------
    >>> values = np.zeros((2, 3, 4), dtype=np.float32)
    >>> image = to_vtk_image(values, spacing=(0.5, 2.0))
    >>> image.GetDimensions(), image.GetSpacing()
    ((3, 2, 1), (0.5, 2.0, 1.0))
    >>> values[1, 2, 0] = 7.0  # shared memory: texel (i, j) = (2, 1) is point 2 + 1 * 3
    >>> image.GetPointData().GetScalars().GetTuple4(5)
    (7.0, 0.0, 0.0, 0.0)
    """
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData

    a = np.ascontiguousarray(_as_hwc(values, "values"), dtype=np.float32)
    flat = a.reshape(-1, a.shape[2])  # a view: C order is VTK's x-fastest point order
    arr = numpy_to_vtk(flat, deep=False)
    arr.SetName(name)
    # numpy_to_vtk only pins the array to this Python wrapper, which VTK drops once the wrapper is
    # gone; an observer is owned by the VTK array itself, so the memory lives exactly as long as it.
    arr.AddObserver("DeleteEvent", lambda _obj, _event, _keep=flat: None)
    img = vtkImageData()
    img.SetDimensions(a.shape[1], a.shape[0], 1)
    img.SetSpacing(float(spacing[0]), float(spacing[1]), 1.0)
    img.SetOrigin(float(origin[0]), float(origin[1]), 0.0)
    img.GetPointData().SetScalars(arr)
    return img


def to_vtk_texture(values, **kwargs):
    """A ``vtkTexture`` that VTK uploads as a float texture with the exact values of ``values``.

    Built on :func:`to_vtk_image` (shared memory, same orientation). Direct scalars, no interpolation,
    no mipmaps and clamped edges, so a shader's ``texelFetch`` sees the float32 values unchanged.

    Parameters
    ----------
    values : (H, W) or (H, W, C) array_like, C in 1..4
    **kwargs
        Passed to :func:`to_vtk_image`.

    Returns
    -------
    vtkTexture

    Examples
    --------
    >>> texture = to_vtk_texture(np.ones((2, 2)))
    >>> texture.GetInput().GetDimensions(), texture.GetInterpolate(), texture.GetMipmap()
    ((2, 2, 1), 0, False)
    """
    from vtkmodules.vtkRenderingCore import vtkTexture

    tex = vtkTexture()
    tex.SetInputData(to_vtk_image(values, **kwargs))
    tex.SetColorModeToDirectScalars()
    tex.InterpolateOff()
    tex.MipmapOff()
    tex.RepeatOff()
    tex.EdgeClampOn()
    return tex


def _image_texture(image: np.ndarray, *, interpolate: bool, repeat: bool = False):
    """An 8-bit image (H, W, C), top row first, as a VTK texture (colormaps, textures, environment maps)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkRenderingCore import vtkTexture

    arr = np.ascontiguousarray(image[::-1])  # image rows run top-down, texture rows bottom-up
    h, w, c = arr.shape
    img = vtkImageData()
    img.SetDimensions(w, h, 1)
    img.GetPointData().SetScalars(numpy_to_vtk(arr.reshape(-1, c), deep=True))
    tex = vtkTexture()
    tex.SetInputData(img)
    tex.SetColorModeToDirectScalars()
    tex.SetInterpolate(bool(interpolate))
    tex.SetRepeat(bool(repeat))
    tex.EdgeClampOn() if not repeat else None
    return tex


def _colormap_image(name: str) -> np.ndarray:
    """A matplotlib colormap as a 1 x 256 RGBA8 image."""
    import matplotlib

    rgba = matplotlib.colormaps[name](np.linspace(0.0, 1.0, 256))
    return (rgba[None, :, :] * 255 + 0.5).astype(np.uint8)
