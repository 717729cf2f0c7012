"""A calibrated model saved to a file, and predictions from it on new data.

``wheelsoil validate`` writes ``model.json`` beside its report: the complete calibrated model (every
:class:`~wheelsoil.validation.terramechanics.SoilParameters` field of the final model and of the calibrated
classical model, the accepted mechanisms, the free parameters with their standard errors), the normalisation
scales of the training data, and the training rows themselves. ``wheelsoil predict MODEL DATA`` rebuilds the
model from the file alone and writes its predictions and errors. JSON numbers are written with Python's
shortest round-trip repr, so the rebuilt model is bit-for-bit the one that was fitted and reproduces its own
predictions exactly.
"""

import csv
import json
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.provenance import atomic_output, provenance

from .calibration import RESPONSES, model_responses
from .measured import GENERIC_COLUMNS, Measurements
from .terramechanics import SoilParameters

FORMAT = "wheelsoil-terramechanics-model/1"


@dataclass
class SavedModel:
    """A calibrated model: the final soil (classical + ``mechanisms``: every accepted mechanism, named as a cause or
    partial; ``named``: those named as causes), the classical one, the responses it was fitted to and their
    normalisation scales [response units]."""

    soil: SoilParameters
    baseline: SoilParameters
    mechanisms: list[str]
    responses: list[str]
    scales: dict[str, float]
    training: dict
    meta: dict
    named: list[str]

    def predict(self, data: Measurements, *, which: str = "final") -> dict[str, np.ndarray]:
        """Responses of the final (or ``which="baseline"``: the classical) model at every row of ``data``."""
        return model_responses(self.soil if which == "final" else self.baseline, data)

    def errors(self, data: Measurements) -> dict:
        """Per response: RMSE [response units] and normalised by the training scale, for the classical and the
        final model, over the rows of ``data`` where the response was measured."""
        out = {}
        preds = {w: self.predict(data, which=w) for w in ("baseline", "final")}
        for q in self.responses:
            y = data.responses.get(q)
            ok = np.isfinite(y) if y is not None else np.zeros(len(data), bool)
            if not ok.any():
                continue
            row = {"rows": int(ok.sum())}
            for w, p in preds.items():
                e = p[q][ok] - y[ok]
                row[w] = {"rmse": float(np.sqrt(np.mean(e ** 2))), "bias": float(np.mean(e)),
                          "nrmse": float(np.sqrt(np.mean(e ** 2)) / self.scales[q])}
            out[q] = row
        return out


def _data_table(data: Measurements) -> dict:
    cols = {GENERIC_COLUMNS[k]: np.asarray(getattr(data, k), float).tolist()
            for k in ("slip", "slip_angle", "load", "gravity", "passes", "radius", "width", "grouser_height",
                      "grouser_count")}
    cols |= {GENERIC_COLUMNS[q]: [None if not np.isfinite(v) else float(v) for v in data.responses[q]]
             for q in RESPONSES}
    cols["group"] = [str(g) for g in data.group]
    return {"name": data.name, "rows": len(data), "columns": cols}


def save_model(path: str | Path, discovery, train: Measurements, *, command: str = "") -> Path:
    """Write the discovery's final model, its classical model and the training rows to ``path`` (JSON)."""
    doc = {
        "format": FORMAT,
        # every mechanism in the final model's soil: those named as causes and those accepted as partial
        "mechanisms": [n for c in discovery.accepted for n in c.names],
        "named": discovery.found,
        "soil": asdict(discovery.final.soil),
        "baseline_soil": asdict(discovery.baseline.soil),
        "responses": list(discovery.responses),
        "scales": {q: float(v) for q, v in discovery.scales.items()},
        "parameters": discovery.final.parameter_table(),
        "baseline_parameters": discovery.baseline.parameter_table(),
        "ambiguities": discovery.ambiguities,
        "unexplained": [u["text"] for u in discovery.unexplained],
        "training_data": _data_table(train),
        "command": command,
        "provenance": provenance(),
    }
    path = Path(path)
    with atomic_output(path) as tmp:
        tmp.write_text(json.dumps(doc, indent=1, default=float))
    return path


def _soil(values: dict, path) -> SoilParameters:
    known = {f.name for f in fields(SoilParameters)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise WheelsoilInputError(f"{path}: unknown soil parameter(s) {unknown}: the file was written by another "
                                  "version of wheelsoil")
    return SoilParameters(**values)


def load_model(path: str | Path) -> SavedModel:
    """Read a model file written by :func:`save_model`; a clear error for anything else."""
    path = Path(path)
    if not path.is_file():
        raise WheelsoilInputError(f"model file {str(path)!r} does not exist (wheelsoil validate writes model.json in "
                                  "its --report folder)")
    try:
        doc = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise WheelsoilInputError(f"{path}: not a model file (not JSON: {exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise WheelsoilInputError(f"{path}: not a wheelsoil model file (format {doc.get('format') if isinstance(doc, dict) else None!r}, "
                                  f"expected {FORMAT!r})")
    return SavedModel(_soil(doc["soil"], path), _soil(doc["baseline_soil"], path), list(doc["mechanisms"]),
                      list(doc["responses"]), {q: float(v) for q, v in doc["scales"].items()}, doc["training_data"],
                      {k: doc.get(k) for k in ("command", "provenance", "parameters", "ambiguities", "unexplained")},
                      # a file without "named" listed only the named mechanisms
                      list(doc.get("named", doc["mechanisms"])))


def write_predictions(model: SavedModel, data: Measurements, out: str | Path) -> tuple[Path, dict]:
    """``predictions.csv`` (conditions, measured, classical and final predictions per response) and the errors
    dict; returns the CSV's path and the errors."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    preds = {w: model.predict(data, which=w) for w in ("baseline", "final")}
    header = ["slip", "travel_slip", "slip_angle_deg", "vertical_load_N", "gravity_m_s2", "passes", "wheel_radius_m",
              "group"]
    cols = [data.slip, data.travel_slip, data.slip_angle, data.load, data.gravity, data.passes, data.radius, data.group]
    for q in model.responses:
        unit = GENERIC_COLUMNS[q].rsplit("_", 1)[-1]
        header += [f"measured_{q}_{unit}", f"classical_{q}_{unit}", f"model_{q}_{unit}"]
        cols += [data.responses[q], preds["baseline"][q], preds["final"][q]]
    path = out / "predictions.csv"
    with atomic_output(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for k in range(len(data)):
            w.writerow([c[k] if isinstance(c[k], str) else repr(float(c[k])) for c in cols])
    return path, model.errors(data)
