"""Result files: one HDF5 file per run (architecture layout) with an XDMF sidecar for ParaView.

Layout (``../shared/docs/architecture.md``; wheelsoil's additions marked +)::

    /                 attrs: case_toml (the resolved case), version, git_rev, taichi_version, arch, seed,
                      created; + case_name, case_hash, bed, complete (True only in a finished file)
    /series/<name>    1-D float64 datasets over time, attr units (coupling.testbed.SERIES_UNITS)
    /summary          attrs: <q>_mean, <q>_std, <q>_sem (standard error), <q>_drift, <q>_units for the
                      steady quantities (tread_slip among them); + <q>_ci95 (half-width of the mean's 95 %
                      confidence interval, Student's t), <q>_dof (its degrees of freedom), <q>_drift_sem,
                      <q>_zero_within_noise (bool: steady as a value indistinguishable from zero,
                      coupling.steady); window_start,
                      window_end [s], steady (bool), samples; + pitches (whole pitches of the tread in the
                      window), pitch_deg, commanded_slip, commanded_slip_angle, reasons (JSON list: why not steady)
    /stages/<k>/      + only for a drive of several stages (``[[protocol.stages]]``, a slip ramp): attrs as
                      /summary's, one group per stage in order (``000``, ``001``, ...); /summary is the last's
    /run              + attrs: wall time, step counts, sizes (coupling.testbed_result.TestbedResult.info)
                      (and resumed_from, frames_lost_before [s]: a run continued from a checkpoint, one carried
                      to another machine without its earlier frames, cases.carry)
    /mesh/            nodes0 (N, 3) [m] (wheel in its start pose), triangles (T, 3), beams (B, 2)
    /frames/<k>/      attr t [s]; particles/{position, velocity (float32), radius}, wheel/{nodes,
                      + deflection (float32: node position less the wheel's best-fit rigid motion of
                      nodes0, mass-weighted: its deformation, not its rotation)}

Frames are named with six digits (``000000``...), in time order. A frame's ``radius`` is a hard link to
the previous frame's while the spheres are the same (stored once); a moving soil patch renews spheres,
and the frame after a renewal stores its own.

Writing is atomic: a run writes ``.<name>.partial`` beside the final path and renames it only when
complete, so a crashed or killed run never leaves a file that looks finished (and ``complete`` is
set only in the rename's source). A run with checkpoints keeps its partial file so that ``--resume``
can continue it.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from wheelsoil.coupling.run_summary import RunSummary
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.state_file import attr_value

FRAME_FORMAT = "{:06d}"
STAGE_FORMAT = "{:03d}"
#: The statistics a summary keeps for each steady quantity.
SUMMARY_STATS = ("mean", "std", "sem", "ci95", "dof", "drift", "drift_sem", "zero_within_noise", "units")


def partial_path(path: str | Path) -> Path:
    """Where a result is written until it is complete."""
    path = Path(path)
    return path.with_name(f".{path.name}.partial")


class ResultWriter:
    """Streams one run into the partial file; :meth:`finish` makes it the result.

    Parameters
    ----------
    path: the final result path (``result.h5``).
    attrs: root attributes (case_toml, provenance, seed, ...).
    mesh: wheel mesh arrays ``nodes0``, ``triangles``, ``beams``.
    resume_frames: continue an existing partial file, keeping its first ``resume_frames`` frames
        (the frames written before the checkpoint being resumed); ``None`` starts afresh.
    """

    def __init__(self, path: str | Path, attrs: dict, mesh: dict, *, resume_frames: int | None = None) -> None:
        self.path = Path(path)
        self.partial = partial_path(self.path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if resume_frames is None:
            self.file = h5py.File(self.partial, "w")
            for key, value in attrs.items():
                self.file.attrs[key] = value
            self.file.attrs["complete"] = False
            g = self.file.create_group("mesh")
            g.create_dataset("nodes0", data=np.asarray(mesh["nodes0"], np.float64))
            for key in ("triangles", "beams"):  # int64: the XDMF sidecar declares 8-byte integers
                g.create_dataset(key, data=np.asarray(mesh[key], np.int64).reshape(-1, 3 if key == "triangles" else 2))
            self.file.create_group("frames")
            self.n_frames = 0
        else:
            if not self.partial.is_file():
                raise WheelsoilInputError(f"nothing to resume: {self.partial} is missing; run without --resume")
            try:
                self.file = h5py.File(self.partial, "a")
            except OSError as exc:
                raise WheelsoilInputError(
                    f"the partial result {self.partial} cannot be opened ({exc}); run without --resume") from None
            frames = self.file["frames"]
            for name in sorted(frames):
                if int(name) >= resume_frames:
                    del frames[name]
            self.n_frames = len(frames)
            if self.n_frames != resume_frames:
                self.file.close()
                raise WheelsoilInputError(
                    f"the partial result {self.partial} has {self.n_frames} frames, the checkpoint expects "
                    f"{resume_frames}; run without --resume")
        self._radius = None

    def add_frame(self, t: float, particles: dict, wheel_nodes: np.ndarray, deflection: np.ndarray) -> None:
        """Append a frame: particle ``position``, ``velocity``, ``radius`` and the wheel's nodes."""
        g = self.file["frames"].create_group(FRAME_FORMAT.format(self.n_frames))
        g.attrs["t"] = float(t)
        p = g.create_group("particles")
        p.create_dataset("position", data=np.asarray(particles["position"], np.float64))
        p.create_dataset("velocity", data=np.asarray(particles["velocity"], np.float32))
        radius = np.asarray(particles["radius"], np.float64)
        if self._radius is None and self.n_frames > 0:
            self._radius = self.file["frames"][FRAME_FORMAT.format(self.n_frames - 1)]["particles/radius"]
        if self._radius is not None and self._radius.shape == radius.shape and np.array_equal(self._radius[()], radius):
            p["radius"] = self._radius  # hard link: one copy of the radii while the spheres are the same
        else:  # the first frame, or a moving soil patch has renewed spheres since the last one
            p.create_dataset("radius", data=radius)
            self._radius = p["radius"]
        w = g.create_group("wheel")
        w.create_dataset("nodes", data=np.asarray(wheel_nodes, np.float64))
        w.create_dataset("deflection", data=np.asarray(deflection, np.float32))
        self.n_frames += 1

    def flush(self) -> None:
        self.file.flush()

    def finish(self, series: dict, units: dict, summary: RunSummary, info: dict,
               stages: tuple[RunSummary, ...] = ()) -> Path:
        """Write the series, summary (and, for a drive of several ``stages``, each stage's) and run info, mark
        complete, close and rename; returns the path."""
        f = self.file
        s = f.create_group("series")
        for name, values in series.items():
            s.create_dataset(name, data=np.asarray(values, np.float64))
            s[name].attrs["units"] = units[name]
        _write_summary(f.create_group("summary"), summary)
        if len(stages) > 1:
            g = f.create_group("stages")
            for k, stage in enumerate(stages):
                _write_summary(g.create_group(STAGE_FORMAT.format(k)), stage)
        r = f.create_group("run")
        for key, value in info.items():
            r.attrs[key] = value
        f.attrs["complete"] = True
        f.close()
        os.replace(self.partial, self.path)
        write_xdmf(self.path)
        return self.path

    def abandon(self) -> None:
        """Close without finishing (the partial file stays for --resume)."""
        if self.file.id.valid:
            self.file.close()


def _write_summary(g: h5py.Group, summary: RunSummary) -> None:
    """A summary as the ``summary`` group's attributes (module docstring)."""
    g.attrs["window_start"], g.attrs["window_end"] = summary.window
    g.attrs["steady"] = bool(summary.steady)
    g.attrs["samples"] = int(summary.samples)
    for q, value in summary.to_dict().items():
        if isinstance(value, dict):
            for key, v in value.items():
                g.attrs[f"{q}_{key}"] = v
        elif q not in ("window", "steady", "samples"):
            g.attrs[q] = json.dumps(value) if isinstance(value, (list, tuple)) else value


def _read_summary(g: h5py.Group) -> RunSummary:
    """The summary :func:`_write_summary` wrote as ``g``'s attributes."""
    sa = {k: attr_value(v) for k, v in g.attrs.items()}
    stored = {"window": [sa.pop("window_start"), sa.pop("window_end")], "steady": bool(sa.pop("steady")),
              "samples": int(sa.pop("samples"))}
    for key in [k[:-5] for k in sa if k.endswith("_mean")]:
        stored[key] = {stat: sa.pop(f"{key}_{stat}") for stat in SUMMARY_STATS if f"{key}_{stat}" in sa}
    for key, value in sa.items():
        stored[key] = json.loads(value) if key == "reasons" else value
    return RunSummary.from_dict(stored)


# -------------------------------------------------------------------- reading
@dataclass
class Result:
    """A finished run read back: time series and summary as NumPy (and pandas) objects.

    ``series``: name -> 1-D array; ``units``: name -> unit; ``summary``: the steady-state summary
    (:class:`~wheelsoil.coupling.run_summary.RunSummary`: ``summary.drawbar_pull.mean``, the window, whether it was
    steady);
    ``attrs``: provenance and the resolved case text (``attrs['case_toml']``); ``info``: run figures;
    ``stages``: every stage's summary in order (a drive of several stages, ``[[protocol.stages]]``; one stage:
    ``(summary,)``).
    """

    path: Path
    series: dict
    units: dict
    summary: RunSummary
    attrs: dict
    info: dict
    frame_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    stages: tuple[RunSummary, ...] = ()

    def __post_init__(self) -> None:
        if not self.stages:
            self.stages = (self.summary,)

    @property
    def case(self):
        """The :class:`~wheelsoil.cases.schema.CaseFile` this result was run from."""
        from .schema import case_from_toml

        return case_from_toml(self.attrs["case_toml"], f"{self.path} (case_toml)")

    @property
    def wheel(self):
        """The :class:`~wheelsoil.flexwheel.geometry.WheelGeometry` this result's wheel was made from."""
        from .build import wheel_geometry

        return wheel_geometry(self.case)

    def steady(self, name: str) -> float:
        """Steady-state mean of a quantity."""
        return self.summary.mean(name)

    def to_dataframe(self):
        """The time series as a pandas DataFrame indexed by t [s] (columns named ``name [unit]``)."""
        import pandas as pd

        frame = pd.DataFrame({f"{k} [{self.units[k]}]": v for k, v in self.series.items() if k != "t"})
        frame.index = pd.Index(self.series["t"], name="t [s]")
        return frame

    def summary_row(self, stage: int | None = None) -> dict:
        """One flat row: case name and hash, the steady means and standard deviations, the window; of the run's
        summary, or of stage ``stage`` of its drive (then with the stage's number and commanded slip)."""
        summary = self.summary if stage is None else self.stages[stage]
        row = {"case": self.attrs.get("case_name"), "case_hash": self.attrs.get("case_hash")}
        if stage is not None:
            row.update(stage=stage, commanded_slip=summary.commanded_slip)
        row.update(steady=summary.steady, samples=summary.samples)
        row["window_start"], row["window_end"] = summary.window
        for q, stats in summary.quantities().items():
            row[f"{q}_mean"] = stats.mean
            row[f"{q}_std"] = stats.std
        return row

    def frame(self, k: int) -> dict:
        """Frame ``k`` (negative counts from the end): t, particle position/velocity/radius, wheel nodes,
        deflection, and the wheel's triangles."""
        n = len(self.frame_times)
        if not -n <= k < n:
            raise WheelsoilInputError(f"frame {k} is out of range: the result has {n} frames")
        k %= n
        with h5py.File(self.path, "r") as f:
            g = f["frames"][FRAME_FORMAT.format(k)]
            return {
                "t": float(g.attrs["t"]),
                "position": g["particles/position"][()], "velocity": g["particles/velocity"][()].astype(float),
                "radius": g["particles/radius"][()], "wheel_nodes": g["wheel/nodes"][()],
                "deflection": g["wheel/deflection"][()].astype(float), "triangles": f["mesh/triangles"][()],
            }


def load_result(path: str | Path) -> Result:
    """Read a finished result file (a partial or crashed one is refused, with the reason)."""
    path = Path(path)
    if path.is_dir():
        path = path / "result.h5"
    if not path.is_file():
        hint = " (a partial file exists: the run did not finish; rerun it with --resume)" if partial_path(path).exists() else ""
        raise WheelsoilInputError(f"result file {str(path)!r} does not exist{hint}")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise WheelsoilInputError(f"{path} is not a readable HDF5 result ({exc})") from None
    with f:
        if not f.attrs.get("complete", False):
            raise WheelsoilInputError(f"{path} is not a complete result (the run did not finish)")
        series = {k: f["series"][k][()] for k in f["series"]}
        units = {k: attr_value(f["series"][k].attrs["units"]) for k in f["series"]}
        summary = _read_summary(f["summary"])
        stages = tuple(_read_summary(f["stages"][k]) for k in sorted(f["stages"])) if "stages" in f else ()
        attrs = {k: attr_value(v) for k, v in f.attrs.items()}
        info = {k: attr_value(v) for k, v in f["run"].attrs.items()}
        times = np.array([f["frames"][k].attrs["t"] for k in sorted(f["frames"])])
    return Result(path=path, series=series, units=units, summary=summary, attrs=attrs, info=info, frame_times=times,
                  stages=stages)


# -------------------------------------------------------------------- XDMF sidecar
def write_xdmf(path: str | Path) -> Path:
    """Write ``<result>.xdmf`` beside a result: particles (points with velocity and radius) and the
    wheel (triangles with deflection) over time; ParaView opens it with the XDMF3 reader."""
    from wheelsoil.provenance import atomic_output

    path = Path(path)
    name = path.name
    with h5py.File(path, "r") as f:
        frames = [(k, float(f["frames"][k].attrs["t"]), f["frames"][k]["particles/position"].shape[0])
                  for k in sorted(f["frames"])]
        n_nodes = f["mesh/nodes0"].shape[0]
        n_tri = f["mesh/triangles"].shape[0]
    steps = []
    for k, t, n in frames:
        base = f"{name}:/frames/{k}"
        steps.append(f"""    <Grid Name="frame {k}" GridType="Collection" CollectionType="Spatial">
      <Time Value="{t!r}"/>
      <Grid Name="particles" GridType="Uniform">
        <Topology TopologyType="Polyvertex" NumberOfElements="{n}" NodesPerElement="1"/>
        <Geometry GeometryType="XYZ">
          <DataItem Dimensions="{n} 3" NumberType="Float" Precision="8" Format="HDF">{base}/particles/position</DataItem>
        </Geometry>
        <Attribute Name="velocity" AttributeType="Vector" Center="Node">
          <DataItem Dimensions="{n} 3" NumberType="Float" Precision="4" Format="HDF">{base}/particles/velocity</DataItem>
        </Attribute>
        <Attribute Name="radius" AttributeType="Scalar" Center="Node">
          <DataItem Dimensions="{n}" NumberType="Float" Precision="8" Format="HDF">{base}/particles/radius</DataItem>
        </Attribute>
      </Grid>
      <Grid Name="wheel" GridType="Uniform">
        <Topology TopologyType="Triangle" NumberOfElements="{n_tri}">
          <DataItem Dimensions="{n_tri} 3" NumberType="Int" Precision="8" Format="HDF">{name}:/mesh/triangles</DataItem>
        </Topology>
        <Geometry GeometryType="XYZ">
          <DataItem Dimensions="{n_nodes} 3" NumberType="Float" Precision="8" Format="HDF">{base}/wheel/nodes</DataItem>
        </Geometry>
        <Attribute Name="deflection" AttributeType="Vector" Center="Node">
          <DataItem Dimensions="{n_nodes} 3" NumberType="Float" Precision="4" Format="HDF">{base}/wheel/deflection</DataItem>
        </Attribute>
      </Grid>
    </Grid>""")
    text = f"""<?xml version="1.0" ?>
<!-- wheelsoil result {name}: particles and the deforming wheel over time (open in ParaView) -->
<Xdmf Version="3.0">
  <Domain>
    <Grid Name="run" GridType="Collection" CollectionType="Temporal">
{chr(10).join(steps)}
    </Grid>
  </Domain>
</Xdmf>
"""
    out = path.with_suffix(".xdmf")
    with atomic_output(out) as tmp:
        tmp.write_text(text)
    return out
