"""Hierarchical view-frustum culling of an isosurface's proxies by the min-max octree (paper 003, sec. 5.1:
"Octree nodes are recursively tested against the viewing frustum during the rendering: if a node is
identified as being outside, the corresponding branch of the tree is truncated").

The relevant cubes are grouped into blocks of ``2^level`` cubes per axis (the paper's fixed octree level
theta). Before every frame the octree nodes holding relevant blocks are tested against the camera's six
frustum planes from the root down: a node entirely outside one plane is dropped with its subtree, a node
entirely inside all planes keeps its whole subtree without further tests, and the rest descend. The proxy
triangles of the visible blocks are handed to the mapper; the cell array is rebuilt only when the visible
set changes. The float64 octree test is conservative (a node's box encloses its cubes), so culling never
removes a visible pixel: images with and without culling are identical (tested).
"""

from __future__ import annotations

import numpy as np

__all__ = ["FrustumCuller", "default_level"]


def default_level(shape) -> int:
    """theta such that the volume is about 16 blocks across its largest axis."""
    return int(max(0, np.ceil(np.log2(max(shape) / 16.0))))


class FrustumCuller:
    """Culls the proxy triangles of a :class:`~splinevis.gl.inject.SplineActor` drawing an isosurface.

    Parameters
    ----------
    actor : SplineActor
        Its ``model`` is an :class:`~splinevis.volume.program.Isosurface`.
    level : int, optional
        Block level theta (default :func:`default_level`).

    Attributes
    ----------
    visible_cubes : int
        Proxy boxes (cubes or blocks) drawn in the last frame; ``tests`` counts nodes tested.
    """

    def __init__(self, actor, level: int | None = None):
        self.actor = actor
        spline = actor.model.spline
        self.level = default_level(spline.shape) if level is None else int(level)
        self.spacing = spline.spacing
        self._key = None
        self.visible_cubes = 0
        self.tests = 0
        self.enabled = True
        self._observer = None
        self.refresh()

    def refresh(self) -> None:
        """Re-read the proxy boxes (after :func:`~splinevis.volume.program.set_isovalue`)."""
        from .program import BLOCK_SIZE, proxy_units

        spec = self.actor.spec
        blocks = bool(spec.defines.get("SV_VOLUME_BLOCKS"))
        B = int(spec.uniforms.get("sv_block_size", BLOCK_SIZE)) if blocks else 1
        # a culling node must enclose every proxy box assigned to it: theta >= log2(block size)
        self.level = max(self.level, int(np.ceil(np.log2(B))))
        first, _ = proxy_units(self.actor.model.spline, self.actor.model.relevant, "blocks" if blocks else "cubes", B)
        self.cubes = first
        self.block_of_cube = first >> self.level  # (n, 3)
        self.blocks, self.cube_block = np.unique(self.block_of_cube, axis=0, return_inverse=True)
        self.cube_block = self.cube_block.ravel()
        self._key = None

    def _node_boxes(self, nodes, lev):
        size = float(1 << lev)
        lo = (nodes * size - 0.5) * self.spacing
        hi = ((nodes + 1) * size - 0.5) * self.spacing
        return lo, hi

    def visible_blocks(self, planes: np.ndarray) -> np.ndarray:
        """Boolean mask over ``self.blocks`` for frustum ``planes`` (6, 4) in the model frame (inward normals:
        a point p is inside when ``planes[:, :3] @ p + planes[:, 3] >= 0`` for all six)."""
        nb = len(self.blocks)
        if nb == 0:
            return np.zeros(0, bool)
        top = int(np.ceil(np.log2(max(1, int(self.blocks.max()) + 1)))) if nb else 0
        keep = np.zeros(nb, bool)
        # nodes at the current level, as (node index (3,), list of block ids below it)
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
            # positive vertex (farthest along the normal) and negative vertex per node and plane
            pos = np.where(n_a[None] >= 0, hi[:, None, :], lo[:, None, :])
            neg = np.where(n_a[None] >= 0, lo[:, None, :], hi[:, None, :])
            outside = ((pos * n_a[None]).sum(-1) + n_b[None] < 0).any(axis=1)
            inside = ((neg * n_a[None]).sum(-1) + n_b[None] >= 0).all(axis=1)
            next_nodes, next_groups = [], []
            for g, node in enumerate(nodes):
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

    def frustum_planes(self, renderer) -> np.ndarray:
        """The active camera's six planes in the actor's model frame."""
        cam = renderer.GetActiveCamera()
        w, h = renderer.GetSize()
        planes = [0.0] * 24
        cam.GetFrustumPlanes(w / max(h, 1), planes)
        P = np.array(planes, dtype=np.float64).reshape(6, 4)
        P[:, 3] += P[:, :3] @ self.actor.offset  # world = model + offset
        return P

    def update(self, renderer) -> None:
        """Cull for the renderer's current camera (called before each frame once attached)."""
        if not self.enabled:
            visible = np.ones(len(self.blocks), bool)
        else:
            visible = self.visible_blocks(self.frustum_planes(renderer))
        key = visible.tobytes()
        if key == self._key:
            return
        self._key = key
        cube_vis = visible[self.cube_block] if len(self.cube_block) else np.zeros(0, bool)
        self.visible_cubes = int(cube_vis.sum())
        cube_ids = np.nonzero(cube_vis)[0]
        from .program import _BOX_TRIS

        tris = (cube_ids[:, None, None] * 8 + _BOX_TRIS[None]).reshape(-1, 3)
        self.actor.set_triangles(tris)

    def attach(self, renderer) -> None:
        """Cull before every frame of ``renderer`` (a vtkRenderer StartEvent observer)."""
        from vtkmodules.vtkCommonCore import vtkCommand

        self._observer = renderer.AddObserver(vtkCommand.StartEvent, lambda *_: self.update(renderer))
