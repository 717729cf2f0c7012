"""Offscreen renders of particle states with pyvista (no display needed).

On a machine without an X display VTK needs an offscreen OpenGL: Mesa's EGL (Debian packages
``libegl1 libgl1-mesa-dri``) or OSMesa (``libosmesa6``). When ``DISPLAY`` is unset this module
selects whichever of the two is installed (``VTK_DEFAULT_OPENGL_WINDOW``), so no X connection is
attempted. ``.ci/run`` installs the EGL packages.
"""

from __future__ import annotations

import ctypes.util
import os
from pathlib import Path

import numpy as np


def _select_offscreen_backend() -> None:
    if os.environ.get("DISPLAY") or os.environ.get("VTK_DEFAULT_OPENGL_WINDOW"):
        return
    if ctypes.util.find_library("EGL"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"
    elif ctypes.util.find_library("OSMesa"):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkOSOpenGLRenderWindow"


_select_offscreen_backend()

CAMERA_PRESETS = {
    # (position direction from the focal point, view-up)
    "iso": ((1.0, -1.6, 1.1), (0.0, 0.0, 1.0)),
    "side": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "top": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "front": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
}


def render_particles(
    positions: np.ndarray,
    radii: np.ndarray,
    path: str | Path,
    *,
    scalars: np.ndarray | None = None,
    scalar_name: str = "height [m]",
    box: tuple | None = None,
    camera: str = "iso",
    size: tuple[int, int] = (1200, 800),
    sphere_resolution: int = 12,
    title: str | None = None,
    surface: tuple[np.ndarray, np.ndarray] | None = None,
) -> Path:
    """Render spheres (coloured by ``scalars``, default height) to a PNG; returns the path.

    ``box`` = ((xmin, ymin, zmin), (xmax, ymax, zmax)) draws the bin outline. ``camera`` is one of
    :data:`CAMERA_PRESETS`. ``surface`` = (nodes (N, 3), triangles (T, 3)) adds a steel-grey
    triangulated surface (the wheel).
    """
    import pyvista as pv

    if camera not in CAMERA_PRESETS:
        raise ValueError(f"camera = {camera!r} is not a preset; choose one of {sorted(CAMERA_PRESETS)}")
    positions = np.asarray(positions, dtype=float)
    radii = np.asarray(radii, dtype=float)
    values = positions[:, 2] if scalars is None else np.asarray(scalars, dtype=float)
    cloud = pv.PolyData(positions)
    cloud["diameter"] = 2.0 * radii
    cloud[scalar_name] = values
    glyphs = cloud.glyph(
        scale="diameter", orient=False, factor=1.0,
        geom=pv.Sphere(radius=0.5, theta_resolution=sphere_resolution, phi_resolution=sphere_resolution),
    )
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    plotter.add_mesh(glyphs, scalars=scalar_name, cmap="viridis", smooth_shading=True,
                     scalar_bar_args={"title": scalar_name, "color": "black"})
    if surface is not None:
        nodes, tris = np.asarray(surface[0], float), np.asarray(surface[1], np.int64)
        faces = np.hstack([np.full((len(tris), 1), 3, np.int64), tris]).ravel()
        plotter.add_mesh(pv.PolyData(nodes, faces), color="#9aa3ad", smooth_shading=False, show_edges=True,
                         edge_color="#5b6168", line_width=0.5)
    if box is not None:
        lo, hi = np.asarray(box[0], float), np.asarray(box[1], float)
        plotter.add_mesh(pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])).outline(), color="black",
                         line_width=2)
    if title:
        plotter.add_text(title, font_size=10, color="black")
    direction, up = CAMERA_PRESETS[camera]
    centre = positions.mean(axis=0) if box is None else 0.5 * (np.asarray(box[0]) + np.asarray(box[1]))
    extent = float(np.ptp(positions, axis=0).max()) if box is None else float(np.max(np.subtract(box[1], box[0])))
    d = np.asarray(direction, float)
    plotter.camera_position = [tuple(centre + d / np.linalg.norm(d) * 2.2 * extent), tuple(centre), up]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def render_bed(bed, path: str | Path, **kwargs) -> Path:
    """Render a prepared :class:`~wheelsoil.granular.Bed` inside its bin outline."""
    s = bed.spec
    kwargs.setdefault("title", bed.summary())
    return render_particles(
        bed.positions, bed.radii, path, box=((0, 0, 0), (s.length, s.width, bed.surface_height)), **kwargs
    )


def render_testbed(result, path: str | Path, **kwargs) -> Path:
    """Render the end of a testbed run: the wheel over the particles, coloured by speed [m/s].

    ``result`` is a :class:`~wheelsoil.coupling.testbed.TestbedResult`.
    """
    p = result.final_particles
    speed = np.linalg.norm(p["velocity"], axis=1)
    lo, hi = p["position"].min(axis=0) - p["radius"].max(), p["position"].max(axis=0) + p["radius"].max()
    hi[2] = max(hi[2], float(result.final_wheel_nodes[:, 2].max()))
    kwargs.setdefault("title", f"{result.bed_summary.split(':')[0]}; t = {result.info['simulated_seconds']:.2f} s")
    return render_particles(p["position"], p["radius"], path, scalars=speed, scalar_name="speed [m/s]",
                            box=(lo, hi), surface=(result.final_wheel_nodes, result.mesh.triangles),
                            **kwargs)
