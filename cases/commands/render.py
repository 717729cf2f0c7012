"""``wheelsoil render``: a result's frame or animation, or a bed file, rendered offscreen."""

from __future__ import annotations

from pathlib import Path

from . import common


def add_parser(sub) -> None:
    """The ``render`` command on ``sub``."""
    p = sub.add_parser("render", help="render a result (a frame, or an animation) or a bed file offscreen",
                       description="Render offscreen (no display needed). A result (result.h5 or its run folder): "
                                   "one frame to PNG -- particles coloured by speed (or height), the wheel by its "
                                   "deflection (displacement less the hub's rigid motion) -- or, with --animate, "
                                   "every frame to a GIF or MP4 (the --out suffix picks; MP4 uses imageio-ffmpeg's "
                                   "own ffmpeg). A bed file: its particles coloured by height.")
    p.add_argument("path", type=Path, help="result.h5, a run folder, or a bed file written by prepare-bed")
    p.add_argument("--out", type=Path, default=None,
                   help="file to write (default: frame.png, animation.gif or <bed>.png beside the input)")
    p.add_argument("--frame", type=int, default=-1, help="result frame to render (default -1: the last)")
    p.add_argument("--animate", action="store_true", help="render every frame of a result to --out (.gif or .mp4)")
    p.add_argument("--fps", type=float, default=10.0, help="animation frames per second (default 10)")
    p.add_argument("--color", default="speed", help="particle colour: speed (default) or height")
    p.add_argument("--wheel-color", default="deflection", help="wheel colour: deflection (default) or none")
    p.add_argument("--camera", default="iso", help="camera preset: iso, side, top, front (default iso)")
    p.add_argument("--size", type=int, nargs=2, default=(1200, 800), metavar=("W", "H"), help="image size in pixels")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    import h5py

    from ..render import CAMERA_PRESETS, PARTICLE_COLORS

    if args.camera not in CAMERA_PRESETS:
        raise common.InputError(f"--camera {args.camera!r} is not a preset; choose one of {sorted(CAMERA_PRESETS)}")
    if args.color not in PARTICLE_COLORS:
        raise common.InputError(f"--color {args.color!r}; choose one of {sorted(PARTICLE_COLORS)}")
    if args.wheel_color not in ("deflection", "none"):
        raise common.InputError(f"--wheel-color {args.wheel_color!r}; choose deflection or none")
    if any(v < 16 or v > 8192 for v in args.size):
        raise common.InputError(f"--size {args.size[0]} {args.size[1]}: each side must lie in [16, 8192] pixels")
    if not (0 < args.fps <= 120):
        raise common.InputError(f"--fps {args.fps} must lie in (0, 120]")
    console = common.console()
    path = args.path / "result.h5" if args.path.is_dir() else args.path
    is_result = False
    if path.is_file():
        try:
            with h5py.File(path, "r") as f:
                is_result = "case_toml" in f.attrs
        except OSError:
            raise common.InputError(f"{path} is not an HDF5 file (a result or a bed)") from None
    size = tuple(args.size)
    if is_result:
        from wheelsoil.provenance import writable_file

        from ..render import render_animation, render_result_frame
        from ..results import load_result

        result = load_result(path)
        wheel = None if args.wheel_color == "none" else "deflection"
        if args.animate:
            out = args.out or path.parent / "animation.gif"
            if out.suffix.lower() not in (".gif", ".mp4"):
                raise common.InputError(f"--out {out}: an animation is a .gif or .mp4 file")
            writable_file(out)
            with common.progress(console) as bar:
                task = bar.add_task("rendering frames", total=len(result.frame_times))
                render_animation(result, out, fps=args.fps, color=args.color, wheel_color=wheel, camera=args.camera,
                                 size=size, progress=lambda k, n: bar.update(task, completed=k))
        else:
            out = writable_file(args.out or path.parent / "frame.png")
            render_result_frame(result, out, frame=args.frame, color=args.color, wheel_color=wheel,
                                camera=args.camera, size=size)
        console.print(f"wrote {out}")
        return common.EXIT_OK
    if args.animate:
        raise common.InputError(f"--animate needs a result file; {path} is not one")
    from wheelsoil.provenance import writable_file
    from wheelsoil.granular import load_bed

    from ..render import render_bed

    out = writable_file(args.out or path.with_suffix(".png"))
    bed = load_bed(path)
    console.print(f"wrote {render_bed(bed, out, camera=args.camera, size=size)}")
    return common.EXIT_OK
