"""Hierarchical view-frustum culling of proxy boxes that sit on a regular grid of cells.

Proxy units (a volume's blocks or cubes, later the walkthrough's patch groups) are grouped into blocks of
``2^level`` cells per axis; before every frame the nodes of the implicit octree over those blocks are tested
against the camera's six frustum planes from the root down [Kalbe2008, sec. 5.1]: a node entirely outside one
plane is dropped with its subtree, a node entirely inside all planes keeps its whole subtree without further
tests, and the rest descend. A node's box encloses its cells, so the float64 test is conservative: culling
never removes a visible pixel. ``on_change`` gets the visible units only when the set changes.

The grid may sit in the world rotated (a volume on a rotated lattice): with ``rotation`` R the world point of
a model point p is ``offset + R p``, and the planes are mapped into the model frame (a plane ``n . w + d >= 0``
becomes ``(R^T n) . p + d + n . offset >= 0``), so the boxes are still tested axis-aligned in their own frame;
a rigid motion keeps the test exact.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FrustumCuller", "default_level"]


def default_level(shape) -> int:
    """Block level theta such that the grid is about 16 blocks across its largest axis.

    Examples
    --------
    >>> default_level((256, 256, 100)), default_level((10, 10, 10))  # blocks of 16^3 cells; of single cells
    (4, 0)
    """
    return int(max(0, np.ceil(np.log2(max(shape) / 16.0))))


class FrustumCuller:
    """Culls proxy units on a grid of cells against a camera frustum.

    Parameters
    ----------
    units : (n, 3) int array_like
        The grid cell (i, j, k) each proxy unit starts at; a unit must lie inside one block of ``2^level``
        cells (raise ``min_level`` to the log2 of the unit size).
    spacing, origin : (3,) array_like
        Cell (i, j, k) covers ``origin + [i, i + 1] * spacing`` ... in the model frame.
    level : int, optional
        Block level theta (default :func:`default_level` of ``grid_shape``).
    grid_shape : tuple, optional
        For the default level.
    min_level : int
    offset : (3,) array_like
        World position of the model frame's origin.
    rotation : (3, 3) array_like, optional
        World-from-model rotation (orthonormal): world = ``offset + rotation @ p``; None for the identity.
    on_change : callable
        ``on_change(visible)`` with a boolean mask over ``units``.

    Attributes
    ----------
    visible_units : int
        Units drawn in the last frame; ``tests`` counts nodes tested.

    Examples
    --------
    >>> import numpy as np
    >>> units = np.array([[0, 0, 0], [40, 0, 0]])
    >>> c = FrustumCuller(units, spacing=(1, 1, 1), level=2)
    >>> half_space_x_below_10 = np.array([[-1.0, 0, 0, 10.0]] * 6)
    >>> c.visible(half_space_x_below_10).tolist()
    [True, False]
    """

    def __init__(self, units, *, spacing, origin=(0.0, 0.0, 0.0), level=None, grid_shape=None, min_level=0,
                 offset=(0.0, 0.0, 0.0), rotation=None, on_change=None):
        self.spacing = np.asarray(spacing, dtype=np.float64).reshape(3)
        self.origin = np.asarray(origin, dtype=np.float64).reshape(3)
        self.offset = np.asarray(offset, dtype=np.float64).reshape(3)
        self.rotation = None
        if rotation is not None:
            R = np.asarray(rotation, dtype=np.float64).reshape(3, 3)
            if np.abs(R.T @ R - np.eye(3)).max() > 1e-9:
                raise ValueError(f"rotation must be orthonormal (a rigid motion), got {R.tolist()}.")
            self.rotation = R
        if level is None:
            level = default_level(grid_shape) if grid_shape is not None else 0
        self.level = max(int(level), int(min_level))
        self.on_change = on_change
        self.enabled = True
        self.visible_units = 0
        self.tests = 0
        self._observer = None
        self.set_units(units)

    def set_units(self, units) -> None:
        """Replace the proxy units (e.g. after an isovalue change); the next update re-culls.

        Examples
        --------
        >>> c = FrustumCuller([[0, 0, 0]], spacing=(1, 1, 1), level=2)
        >>> c.set_units([[40, 0, 0], [41, 3, 0], [0, 0, 0]])
        >>> c.blocks.tolist(), c.unit_block.tolist()  # blocks of 4^3 cells, sorted
        ([[0, 0, 0], [10, 0, 0]], [1, 1, 0])
        """
        self.units = np.asarray(units, dtype=np.int64).reshape(-1, 3)
        self.blocks, inverse = np.unique(self.units >> self.level, axis=0, return_inverse=True)
        self.unit_block = inverse.ravel()
        self._key = None

    def _node_boxes(self, nodes, lev):
        size = float(1 << lev)
        return self.origin + nodes * size * self.spacing, self.origin + (nodes + 1) * size * self.spacing

    def visible_blocks(self, planes: np.ndarray) -> np.ndarray:
        """Boolean mask over ``self.blocks`` for frustum ``planes`` (6, 4) in the model frame (inward normals:
        a point p is inside when ``planes[:, :3] @ p + planes[:, 3] >= 0`` for all six).

        Examples
        --------
        >>> c = FrustumCuller([[0, 0, 0], [40, 0, 0]], spacing=(1, 1, 1), level=2)
        >>> c.visible_blocks(np.array([[1.0, 0, 0, -20.0]] * 6)).tolist(), c.tests  # only x >= 20
        ([False, True], 4)
        """
        nb = len(self.blocks)
        if nb == 0:
            return np.zeros(0, bool)
        top = int(np.ceil(np.log2(max(1, int(self.blocks.max()) + 1))))
        keep = np.zeros(nb, bool)
        ids = np.arange(nb)
        nodes, inv = np.unique(self.blocks >> top, axis=0, return_inverse=True)
        groups = [ids[inv.ravel() == g] for g in range(len(nodes))]
        n_a, n_b = planes[:, :3], planes[:, 3]
        self.tests = 0
        for lev in range(top, -1, -1):
            if not groups:
                break
            lo, hi = self._node_boxes(nodes, lev + self.level)
            self.tests += len(nodes)
            # the box corner farthest along each plane normal (positive vertex) and the nearest one
            pos = np.where(n_a[None] >= 0, hi[:, None, :], lo[:, None, :])
            neg = np.where(n_a[None] >= 0, lo[:, None, :], hi[:, None, :])
            outside = ((pos * n_a[None]).sum(-1) + n_b[None] < 0).any(axis=1)
            inside = ((neg * n_a[None]).sum(-1) + n_b[None] >= 0).all(axis=1)
            next_nodes, next_groups = [], []
            for g in range(len(nodes)):
                if outside[g]:
                    continue
                if inside[g] or lev == 0:
                    keep[groups[g]] = True
                    continue
                sub = self.blocks[groups[g]] >> (lev - 1)
                child, cinv = np.unique(sub, axis=0, return_inverse=True)
                for c in range(len(child)):
                    next_nodes.append(child[c])
                    next_groups.append(groups[g][cinv.ravel() == c])
            nodes = np.array(next_nodes).reshape(-1, 3)
            groups = next_groups
        return keep

    def visible(self, planes: np.ndarray) -> np.ndarray:
        """Boolean mask over the units for frustum ``planes`` (model frame).

        Examples
        --------
        >>> c = FrustumCuller([[0, 0, 0], [1, 0, 0], [40, 0, 0]], spacing=(1, 1, 1), level=2)
        >>> c.visible(np.array([[-1.0, 0, 0, 10.0]] * 6)).tolist()  # only x <= 10
        [True, True, False]
        """
        blocks = self.visible_blocks(planes)
        return blocks[self.unit_block] if len(self.unit_block) else np.zeros(0, bool)

    def model_planes(self, world_planes) -> np.ndarray:
        """World planes (6, 4) mapped into the model frame (world = ``offset + rotation @ p``).

        Examples
        --------
        >>> quarter_turn = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]  # model +x is world +y
        >>> c = FrustumCuller([[0, 0, 0]], spacing=(1, 1, 1), offset=(0, 5, 0), rotation=quarter_turn)
        >>> c.model_planes(np.array([[0.0, 1.0, 0.0, -7.0]])).tolist()  # world y >= 7: model x >= 2
        [[1.0, 0.0, 0.0, -2.0]]
        """
        P = np.array(world_planes, dtype=np.float64).reshape(-1, 4)
        P[:, 3] += P[:, :3] @ self.offset  # n . (offset + R p) + d
        if self.rotation is not None:
            P[:, :3] = P[:, :3] @ self.rotation  # rows n^T R = (R^T n)^T
        return P

    def frustum_planes(self, renderer) -> np.ndarray:
        """The renderer's active camera's six planes in the model frame (:meth:`model_planes`).

        Examples
        --------
        >>> from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
        >>> renderer, window = vtkRenderer(), vtkRenderWindow()
        >>> window.SetSize(100, 100); window.AddRenderer(renderer)
        >>> renderer.GetActiveCamera().SetPosition(0, 0, 50)  # looking down -z at the origin
        >>> planes = FrustumCuller([[0, 0, 0]], spacing=(1, 1, 1)).frustum_planes(renderer)
        >>> planes.shape, bool((planes[:, :3] @ [0, 0, 0] + planes[:, 3] >= 0).all())  # the origin is inside
        ((6, 4), True)
        """
        cam = renderer.GetActiveCamera()
        w, h = renderer.GetSize()
        planes = [0.0] * 24
        cam.GetFrustumPlanes(w / max(h, 1), planes)
        return self.model_planes(planes)

    def update(self, renderer) -> None:
        """Cull for the renderer's current camera; calls ``on_change`` when the visible set changed.

        Examples
        --------
        >>> from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
        >>> renderer, window = vtkRenderer(), vtkRenderWindow()
        >>> window.SetSize(100, 100); window.AddRenderer(renderer)
        >>> renderer.GetActiveCamera().SetPosition(0, 0, 50)  # a 30 degree view: x within +-13 at z = 0
        >>> changes = []
        >>> c = FrustumCuller([[0, 0, 0], [40, 0, 0]], spacing=(1, 1, 1), level=2, on_change=changes.append)
        >>> c.update(renderer); c.update(renderer)  # the second frame changes nothing
        >>> [mask.tolist() for mask in changes], c.visible_units
        ([[True, False]], 1)
        """
        if self.enabled:
            visible = self.visible(self.frustum_planes(renderer))
        else:
            visible = np.ones(len(self.units), bool)
        key = visible.tobytes()
        if key == self._key:
            return
        self._key = key
        self.visible_units = int(visible.sum())
        if self.on_change is not None:
            self.on_change(visible)

    def attach(self, renderer) -> None:
        """Cull before every frame of ``renderer`` (a vtkRenderer StartEvent observer).

        Examples
        --------
        >>> from vtkmodules.vtkCommonCore import vtkCommand
        >>> from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow
        >>> renderer, window = vtkRenderer(), vtkRenderWindow()
        >>> window.SetSize(100, 100); window.AddRenderer(renderer)
        >>> renderer.GetActiveCamera().SetPosition(0, 0, 50)
        >>> c = FrustumCuller([[0, 0, 0], [40, 0, 0]], spacing=(1, 1, 1), level=2)
        >>> c.attach(renderer)
        >>> _ = renderer.InvokeEvent(vtkCommand.StartEvent)  # what every render of the window does first
        >>> c.visible_units
        1
        """
        from vtkmodules.vtkCommonCore import vtkCommand

        self._observer = renderer.AddObserver(vtkCommand.StartEvent, lambda *_: self.update(renderer))
