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


def render_particles(positions: np.ndarray, radii: np.ndarray, path: str | Path, **view) -> Path:
    """Render spheres to a PNG (the view keywords of :func:`render_image`); returns the path."""
    import imageio.v3 as iio

    image = render_image(positions, radii, **view)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, image, extension=".png")
    return path


def render_image(
    positions: np.ndarray,
    radii: np.ndarray,
    *,
    scalars: np.ndarray | None = None,
    scalar_name: str = "height [m]",
    box: tuple | None = None,
    camera: str = "iso",
    size: tuple[int, int] = (1200, 800),
    sphere_resolution: int = 12,
    title: str | None = None,
    surface: tuple[np.ndarray, np.ndarray] | None = None,
    surface_scalars: np.ndarray | None = None,
    surface_scalar_name: str = "wheel deformation [mm]",
    clim: tuple[float, float] | None = None,
    surface_clim: tuple[float, float] | None = None,
    arrows: list | None = None,
    scale_bar: bool = True,
) -> np.ndarray:
    """Spheres (coloured by ``scalars``, default height) as an (H, W, 3) uint8 image.

    ``box`` = ((xmin, ymin, zmin), (xmax, ymax, zmax)) draws the bin outline and, with ``scale_bar``, a
    ruler in metres along its front bottom edge; an axes triad (X, Y, Z) sits in the lower left corner.
    ``camera`` is one of :data:`CAMERA_PRESETS`. ``surface`` = (nodes (N, 3), triangles (T, 3)) adds a
    triangulated surface (the wheel): steel grey, or coloured by the nodal ``surface_scalars``. ``clim`` and
    ``surface_clim`` fix the colour ranges (for animations). ``arrows``: (origin (3,) [m], vector (3,) [m],
    colour, label) tuples drawn as 3-D arrows with their label at the tip (heading and travel, say).
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
    plotter.add_mesh(glyphs, scalars=scalar_name, cmap="viridis", smooth_shading=True, clim=clim,
                     scalar_bar_args={"title": scalar_name, "color": "black", "position_x": 0.05, "width": 0.4})
    if surface is not None:
        nodes, tris = np.asarray(surface[0], float), np.asarray(surface[1], np.int64)
        faces = np.hstack([np.full((len(tris), 1), 3, np.int64), tris]).ravel()
        wheel = pv.PolyData(nodes, faces)
        if surface_scalars is None:
            plotter.add_mesh(wheel, color="#9aa3ad", smooth_shading=False, show_edges=True, edge_color="#5b6168",
                             line_width=0.5)
        else:
            wheel[surface_scalar_name] = np.asarray(surface_scalars, float)
            plotter.add_mesh(wheel, scalars=surface_scalar_name, cmap="inferno", show_edges=True,
                             edge_color="#5b6168", line_width=0.3, clim=surface_clim,
                             scalar_bar_args={"title": surface_scalar_name, "color": "black", "vertical": True,
                                              "position_x": 0.88, "position_y": 0.3, "height": 0.5, "width": 0.06})
    if box is not None:
        lo, hi = np.asarray(box[0], float), np.asarray(box[1], float)
        plotter.add_mesh(pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])).outline(), color="black",
                         line_width=2)
    for origin, vector, colour, label in arrows or ():
        origin, vector = np.asarray(origin, float), np.asarray(vector, float)
        length = float(np.linalg.norm(vector))
        if length <= 0:
            continue
        plotter.add_mesh(pv.Arrow(start=origin, direction=vector / length, scale=length, tip_length=0.25,
                                  tip_radius=0.08, shaft_radius=0.03), color=colour)
        plotter.add_point_labels(pv.PolyData((origin + 1.05 * vector)[None, :]), [label], font_size=14,
                                 text_color=colour, shape=None, show_points=False, always_visible=True)
    if box is not None and scale_bar:
        lo, hi = np.asarray(box[0], float), np.asarray(box[1], float)
        plotter.add_ruler((lo[0], lo[1], lo[2]), (hi[0], lo[1], lo[2]), title="m", font_size_factor=0.5,
                          label_color="black", tick_color="black")
    plotter.add_axes(color="black", line_width=2, labels_off=False)
    if title:
        plotter.add_text(title, font_size=10, color="black")
    direction, up = CAMERA_PRESETS[camera]
    centre = positions.mean(axis=0) if box is None else 0.5 * (np.asarray(box[0]) + np.asarray(box[1]))
    extent = float(np.ptp(positions, axis=0).max()) if box is None else float(np.max(np.subtract(box[1], box[0])))
    d = np.asarray(direction, float)
    plotter.camera_position = [tuple(centre + d / np.linalg.norm(d) * 2.2 * extent), tuple(centre), up]
    image = plotter.screenshot(return_img=True)
    plotter.close()
    return np.asarray(image)[..., :3]


def render_bed(bed, path: str | Path, **kwargs) -> Path:
    """Render a prepared :class:`~wheelsoil.granular.Bed` inside its bin outline."""
    s = bed.spec
    kwargs.setdefault("title", bed.summary())
    return render_particles(
        bed.positions, bed.radii, path, box=((0, 0, 0), (s.length, s.width, bed.surface_height)), **kwargs
    )


def motion_arrows(wheel_nodes: np.ndarray, slip_angle: float) -> list:
    """Arrows (for :func:`render_image`) from above the wheel: its heading (blue; the wheel is yawed by
    -beta, :mod:`wheelsoil.coupling.testbed`) and the carriage's travel along +X (red), 0.6 wheel
    diameters long."""
    size = float(np.ptp(wheel_nodes[:, 0]))
    origin = 0.5 * (wheel_nodes.min(axis=0) + wheel_nodes.max(axis=0)) + np.array([0.0, 0.0, 0.75 * size])
    b = np.radians(slip_angle)
    return [(origin, 0.6 * size * np.array([np.cos(b), -np.sin(b), 0.0]), "#1f5fbf", "heading"),
            (origin, 0.6 * size * np.array([1.0, 0.0, 0.0]), "#c0392b", "travel")]


def render_testbed(result, path: str | Path, **kwargs) -> Path:
    """Render the end of a testbed run: the wheel (coloured by its deformation when the result holds it) over
    the particles (coloured by speed [m/s]), heading and travel arrows, slip and steering in the title.

    ``result`` is a :class:`~wheelsoil.coupling.testbed_result.TestbedResult`.
    """
    p = result.final_particles
    speed = np.linalg.norm(p["velocity"], axis=1)
    lo, hi = p["position"].min(axis=0) - p["radius"].max(), p["position"].max(axis=0) + p["radius"].max()
    nodes = result.final_wheel_nodes
    hi[2] = max(hi[2], float(nodes[:, 2].max()))
    spec = result.spec
    tread = result.summary.tread_slip.mean
    verdict = "steady" if result.summary.steady else "NOT steady"
    kwargs.setdefault("title", f"end of the run, t = {result.info['simulated_seconds']:.2f} s ({verdict}): slip "
                               f"{result.summary.commanded_slip:.2f} commanded, {tread:.3f} at the tread (window "
                               "mean); steering "
                               f"{spec.slip_angle:g} deg")
    kwargs.setdefault("arrows", motion_arrows(nodes, spec.slip_angle))
    if result.final_deformation is not None:
        kwargs.setdefault("surface_scalars", 1e3 * np.linalg.norm(result.final_deformation, axis=1))
    return render_particles(p["position"], p["radius"], path, scalars=speed, scalar_name="speed [m/s]",
                            box=(lo, hi), surface=(nodes, result.mesh.triangles), **kwargs)


PARTICLE_COLORS = {"speed": "speed [m/s]", "height": "height [m]"}


def _frame_view(frame: dict, color: str, wheel_color: str | None):
    if color not in PARTICLE_COLORS:
        raise ValueError(f"color = {color!r}; choose one of {sorted(PARTICLE_COLORS)}")
    if wheel_color not in (None, "deflection"):
        raise ValueError(f"wheel_color = {wheel_color!r}; choose 'deflection' or None")
    p = frame["position"]
    scalars = np.linalg.norm(frame["velocity"], axis=1) if color == "speed" else p[:, 2]
    wheel = 1e3 * np.linalg.norm(frame["deflection"], axis=1) if wheel_color else None
    return scalars, wheel


def result_box(result) -> tuple[np.ndarray, np.ndarray]:
    """A fixed view box for every frame of a result: the bed's extent and the wheel's top."""
    first, last = result.frame(0), result.frame(-1)
    r = float(first["radius"].max())
    lo = first["position"].min(axis=0) - r
    hi = first["position"].max(axis=0) + r
    hi[2] = max(hi[2], float(first["wheel_nodes"][:, 2].max()), float(last["wheel_nodes"][:, 2].max()))
    return lo, hi


def _result_kinematics(result, t: float | None = None) -> tuple[float, float]:
    """(commanded slip, steering angle beta [deg]) of a result's case; for a drive of several stages, the slip of the
    stage running at time ``t`` [s] (the first whose steady window ends at or after ``t``)."""
    test = result.case.test
    slip = float(test.slip)
    if t is not None and len(result.stages) > 1:
        running = [st for st in result.stages if st.window[1] >= t]
        slip = float((running[0] if running else result.stages[-1]).commanded_slip)
    return slip, float(test.slip_angle)


def frame_annotations(result, frame: dict) -> tuple[str, list]:
    """The title and arrows of a frame: commanded slip and steering angle, the slip the tread saw at that
    time (the ``tread_slip`` series, averaged over the last tenth of a second before the frame), and arrows
    for the wheel's heading (blue) and the carriage's travel (+X, red) from above the hub."""
    t = float(frame["t"])
    slip, beta = _result_kinematics(result, t)
    series = result.series
    recent = (series["t"] <= t) & (series["t"] > t - 0.1)
    tread = f"{float(np.mean(series['tread_slip'][recent])):.3f}" if recent.any() else "n/a"
    title = (f"{result.attrs.get('case_name', '')}: t = {t:.2f} s, slip {slip:.2f} commanded / {tread} at the "
             f"tread, steering {beta:g} deg")
    return title, motion_arrows(frame["wheel_nodes"], beta)


def render_result_frame(result, path: str | Path, *, frame: int = -1, color: str = "speed",
                        wheel_color: str | None = "deflection", **kwargs) -> Path:
    """Render frame ``frame`` of a :class:`~wheelsoil.cases.results.Result` to a PNG: particles coloured by
    speed (or height), the wheel by the magnitude of its deformation (displacement less the wheel's
    best-fit rigid motion, so neither the hub's travel nor the tread's rotation shows), arrows for heading and
    travel, the commanded and tread slip and the steering angle in the title (:func:`frame_annotations`)."""
    f = result.frame(frame)
    scalars, wheel = _frame_view(f, color, wheel_color)
    title, arrows = frame_annotations(result, f)
    kwargs.setdefault("title", title)
    kwargs.setdefault("arrows", arrows)
    kwargs.setdefault("box", result_box(result))
    return render_particles(f["position"], f["radius"], path, scalars=scalars, scalar_name=PARTICLE_COLORS[color],
                            surface=(f["wheel_nodes"], f["triangles"]), surface_scalars=wheel, **kwargs)


def render_animation(result, path: str | Path, *, fps: float = 10.0, color: str = "speed",
                     wheel_color: str | None = "deflection", camera: str = "iso", size: tuple[int, int] = (960, 640),
                     progress=None) -> Path:
    """Every frame of a result as an animation: ``.gif`` or ``.mp4`` (H.264 through imageio-ffmpeg's own
    ffmpeg: no system package needed). Colour ranges are fixed over the run; ``progress(k, n)`` is
    called after each frame."""
    import imageio.v2 as imageio

    from wheelsoil.provenance import atomic_output

    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise ValueError(f"animation {path.name!r}: the file must end in .gif or .mp4")
    n = len(result.frame_times)
    box = result_box(result)
    frames = [result.frame(k) for k in range(n)]
    views = [_frame_view(f, color, wheel_color) for f in frames]
    top = max(float(np.percentile(v[0], 99.5)) for v in views)
    clim = (0.0, max(top, 1e-9)) if color == "speed" else (float(box[0][2]), float(box[1][2]))
    surface_clim = (0.0, max(max(float(v[1].max()) for v in views), 1e-9)) if wheel_color else None
    # even pixel sizes: H.264 needs them
    size = (size[0] // 2 * 2, size[1] // 2 * 2)
    with atomic_output(path) as tmp:
        options = {"fps": fps} if path.suffix.lower() == ".mp4" else {"duration": 1.0 / fps, "loop": 0}
        fmt = "FFMPEG" if path.suffix.lower() == ".mp4" else "GIF"
        target = tmp.with_name(tmp.name + path.suffix.lower())  # the writers pick the format from the suffix
        with imageio.get_writer(target, format=fmt, mode="I", **options) as writer:
            for k, (f, (scalars, wheel)) in enumerate(zip(frames, views)):
                title, arrows = frame_annotations(result, f)
                image = render_image(f["position"], f["radius"], scalars=scalars, scalar_name=PARTICLE_COLORS[color],
                                     box=box, camera=camera, size=size, surface=(f["wheel_nodes"], f["triangles"]),
                                     surface_scalars=wheel, clim=clim, surface_clim=surface_clim, title=title,
                                     arrows=arrows)
                writer.append_data(image)
                if progress is not None:
                    progress(k + 1, n)
        os.replace(target, tmp)
    return path
