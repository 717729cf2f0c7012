"""The case file: a TOML description of one testbed run, read, validated by a pydantic schema (the section models
in :mod:`.case_model`), checked against the solver's cross-checks, and written back.

A case has seven sections; every key has a default (the smoke steering run, :mod:`wheelsoil.parameters.smoke`), so
a case file holds only what differs from it. Each key's allowed range is the solver spec's own (``RANGES`` of
``TestbedSpec``, ``BedSpec``, ``WheelGeometry``, ``Material``, ``PairProperties``); :mod:`.build` turns a case into
those specs. ``wheelsoil case show`` prints every key with its unit, range and default.

    [case]      name, description, seed of the bed's random packing
    [soil]      bin size, particle sizes, gravity, particle material and soil--soil friction
    [wheel]     a preset wheel (lunar-rover, exomars), its mesh size, rigid or flexible, any dimension
    [contact]   soil--wheel restitution and friction
    [test]      what the rig does: slip, steering angle, load, wheel speed, timing
    [output]    sampling, steady-state detection, frames kept in the result, checkpoints, the render
    [protocol]  further stages of the drive after the first (a slip ramp: stages = [{slip = 0.3}, {slip = 0.5}])

Values are SI numbers in the key's unit (angles in degrees), or strings with a unit of the same
dimension ("600 ms", "3 kN", "30 %"; :mod:`wheelsoil.cases.units`). Errors name the file, the key,
the value and what is allowed; an unknown key is answered with the closest valid one.

A case plus ``--set section.key=value`` overrides is the whole input of a run; the resolved case
(every key, defaults filled in) is what a result file stores (:func:`case_to_toml`) and its hash
(:meth:`CaseFile.case_hash`) keys finished runs in a sweep.
"""

from __future__ import annotations

import difflib
import json
import math
import sys
from importlib import resources
from pathlib import Path

from pydantic import ValidationError

from wheelsoil.errors import WheelsoilInputError

from . import build
from .case_model import SECTIONS, CaseError, CaseFile, Stage

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


# -------------------------------------------------------------------- reading
def preset_names() -> list[str]:
    """Names of the case presets shipped in ``wheelsoil/cases/presets``."""
    folder = resources.files("wheelsoil.cases") / "presets"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def preset_text(name: str) -> str:
    """The TOML text of a preset case."""
    path = resources.files("wheelsoil.cases") / "presets" / f"{name}.toml"
    if not path.is_file():
        raise CaseError(name, [f"no case file or preset of that name; presets: {', '.join(preset_names())}"])
    return path.read_text()


def read_toml_text(path: Path) -> str:
    """The text of a TOML file; a file that is not UTF-8 text or cannot be read is a :class:`CaseError`."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise CaseError(str(path), [f"not a TOML text file (not UTF-8 text: byte {exc.start} is "
                                    f"{exc.object[exc.start:exc.start + 1]!r})"]) from None
    except OSError as exc:
        raise CaseError(str(path), [f"cannot be read: {exc.strerror or exc}"]) from None


def parse_toml(text: str, source: str) -> dict:
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(source, [f"not valid TOML: {exc}"]) from None


def _suggest(word: str, options, prefix: str = "") -> str:
    close = difflib.get_close_matches(word, list(options), n=1, cutoff=0.5)
    return f"; did you mean {prefix}{close[0]}?" if close else f"; valid keys: {', '.join(options)}"


def _lookup(data: dict, loc: tuple):
    for part in loc:
        if isinstance(data, dict) and part in data:
            data = data[part]
        elif isinstance(data, (list, tuple)) and isinstance(part, int) and part < len(data):
            data = data[part]
        else:
            return None
    return data


def _limits(section: str, key: str, *, with_unit: bool = True, model=None) -> str:
    model = model or SECTIONS.get(section)
    field = model.model_fields.get(key) if model else None
    if field is None:
        return ""
    parts = []
    for meta in field.metadata:
        for attr, sym in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            bound = getattr(meta, attr, None)
            if bound is not None:
                parts.append(f"{sym} {bound:g}")
    unit = (field.json_schema_extra or {}).get("unit")
    text = f"allowed {key} {' and '.join(parts)}" if parts else ""
    if with_unit and unit and unit != "1":
        text += f"{'; ' if text else ''}unit {unit}"
    return f" ({text})" if text else ""


def _messages(exc: ValidationError, data: dict) -> list[str]:
    out = []
    for err in exc.errors():
        loc = tuple(err["loc"])
        # a union's alternatives add their type name to the location; keep the key path only
        path = [p for p in loc if not (isinstance(p, str) and p.endswith("]") or p in ("str", "float", "int"))]
        key = ".".join(str(p) for p in path)
        if err["type"] == "extra_forbidden":
            if len(path) == 1:
                out.append(f"unknown section [{path[0]}]{_suggest(str(path[0]), SECTIONS)}")
            else:
                stage = len(path) == 4 and path[0] == "protocol"
                model = Stage if stage else SECTIONS.get(str(path[0]))
                options = list(model.model_fields) if model else []
                prefix = ".".join(map(str, path[:3])) + "." if stage else f"{path[0]}."
                out.append(f"unknown key {key}{_suggest(str(path[-1]), options, prefix)}")
            continue
        value = _lookup(data, tuple(path))
        if len(path) == 4 and tuple(path[:2]) == ("protocol", "stages"):  # a key of one stage, protocol.stages.<k>.key
            limits = _limits("protocol", str(path[3]), model=Stage)
        else:
            limits = _limits(str(path[0]), str(path[1])) if len(path) >= 2 else ""
        msg = err["msg"].removeprefix("Value error, ")
        out.append(f"{key} = {value!r}: {msg}{limits}")
    # a union reports every alternative; one line per key is enough
    seen, unique = set(), []
    for line in out:
        head = line.split(":")[0]
        if head not in seen:
            seen.add(head)
            unique.append(line)
    return unique


def validate_case(data: dict, source: str, *, default_name: str | None = None) -> CaseFile:
    """Validate a case dictionary (parsed TOML); errors name ``source``, the key and the value."""
    if not isinstance(data, dict):
        raise CaseError(source, ["a case is a TOML table of sections"])
    try:
        case = CaseFile.model_validate(data)
    except ValidationError as exc:
        raise CaseError(source, _messages(exc, data)) from None
    if case.case.name is None:
        name = default_name or "case"
        case = case.model_copy(update={"case": case.case.model_copy(update={"name": name})})
    o = case.output
    for key in ("frame_interval", "checkpoint_interval"):
        value = getattr(o, key)
        if 0 < value < o.sample_interval:
            raise CaseError(source, [f"output.{key} = {value:g} s is shorter than output.sample_interval = "
                                     f"{o.sample_interval:g} s (they are taken at the ends of samples): use 0 "
                                     f"({'the last frame only' if key == 'frame_interval' else 'none'}) or at least "
                                     f"{o.sample_interval:g} s"])
    try:  # the solver's own cross-checks (particle sizes against the bin, wheel proportions, the drive, ...)
        build.plan(case)
    except WheelsoilInputError as exc:
        raise CaseError(source, [str(exc)]) from None
    return case


def parse_override(text: str) -> tuple[list[str], object]:
    """``section.key=value`` -> (["section", "key"], value); the value is read as TOML (``0.3``,
    ``true``, ``[0, 0, -1.62]``, ``"3 kN"``), or taken as a string when it is not TOML (``moon``)."""
    if "=" not in text:
        raise CaseError("--set", [f"{text!r} is not section.key=value (e.g. test.slip=0.3)"])
    key, raw = (s.strip() for s in text.split("=", 1))
    path = [p for p in key.split(".") if p]
    if len(path) != 2:
        raise CaseError("--set", [f"{key!r} is not section.key (sections: {', '.join(SECTIONS)})"])
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return path, value


def apply_overrides(data: dict, overrides) -> dict:
    """A copy of ``data`` with each ``section.key=value`` override (or (path, value) pair) set."""
    data = json.loads(json.dumps(data))  # deep copy of plain TOML data
    for item in overrides or ():
        path, value = parse_override(item) if isinstance(item, str) else item
        section, key = path
        if section not in SECTIONS:
            raise CaseError("--set", [f"unknown section {section!r} in {'.'.join(path)}{_suggest(section, SECTIONS)}"])
        if key not in SECTIONS[section].model_fields:
            raise CaseError("--set", [f"unknown key {'.'.join(path)}"
                                      f"{_suggest(key, list(SECTIONS[section].model_fields), f'{section}.')}"])
        data.setdefault(section, {})[key] = value
    return data


def load_case(spec: str | Path, overrides=(), *, name: str | None = None) -> CaseFile:
    """A case from a TOML file path or a preset name, with ``section.key=value`` overrides applied.

    The case name defaults to the file (or preset) name; ``name`` replaces it.
    """
    path = Path(spec)
    if path.suffix == ".toml" or path.is_file():
        if not path.is_file():
            raise CaseError(str(path), ["no such case file"])
        text, source, stem = read_toml_text(path), str(path), path.stem
    else:
        text, source, stem = preset_text(str(spec)), f"preset {spec}", str(spec)
    data = apply_overrides(parse_toml(text, source), [o for o in overrides])
    if name is not None:
        data.setdefault("case", {})["name"] = name
    where = source + (f" with --set {' '.join(overrides)}" if overrides else "")
    return validate_case(data, where, default_name=stem)


def case_from_toml(text: str, source: str = "case text") -> CaseFile:
    """The case a resolved TOML text (as written by :func:`case_to_toml`) describes."""
    return validate_case(parse_toml(text, source), source)


# -------------------------------------------------------------------- writing
def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf") if math.isinf(value) else "nan"
    if isinstance(value, str):
        return json.dumps(value)  # JSON string escapes are valid TOML basic strings
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):  # an inline table, its unset keys left out
        return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items() if v is not None) + "}"
    raise TypeError(f"no TOML form for {value!r}")


def case_to_toml(case: CaseFile, *, comments: bool = True, template: bool = False) -> str:
    """Every key of ``case`` as TOML (unset optional keys as comments), with units and ranges documented.

    ``case_from_toml(case_to_toml(case)) == case`` (the round trip a result file relies on).
    ``template``: the case name is left as a comment, so that a copy saved as ``my-case.toml`` is named
    ``my-case`` (what ``wheelsoil case show`` prints).
    """
    lines = [f"# wheelsoil case (schema of wheelsoil {_version()}); every key shown, defaults filled in"]
    for section, model in SECTIONS.items():
        values = getattr(case, section)
        if section == "protocol":
            lines += _protocol_lines(values, comments=comments, template=template)
            continue
        lines += ["", f"[{section}]"]
        for key, field in model.model_fields.items():
            value = getattr(values, key)
            unit = (field.json_schema_extra or {}).get("unit")
            note = f"  # [{unit}] {field.description}" if comments and unit else (
                f"  # {field.description}" if comments and field.description else "")
            note += _limits(section, key, with_unit=False).replace(f"allowed {key} ", "") if comments and note else ""
            if value is None:
                lines.append(f"# {key} ={note}")
            elif template and (section, key) == ("case", "name"):
                lines.append(f"# {key} = {_toml_value(value)}{note}")
            else:
                lines.append(f"{key} = {_toml_value(value)}{note}")
    return "\n".join(lines) + "\n"


def _protocol_lines(protocol, *, comments: bool, template: bool) -> list[str]:
    """The ``[protocol]`` section: its stages as inline tables; nothing for a one-stage drive (so the text of a case
    written before the section existed is unchanged), except a commented example in a ``template``."""
    if protocol.stages:
        note = f"  # {type(protocol).model_fields['stages'].description}" if comments else ""
        return ["", "[protocol]", f"stages = {_toml_value([st.model_dump() for st in protocol.stages])}{note}"]
    if template:
        return ["", "# [protocol]", "# stages = [{slip = 0.3}, {slip = 0.5, drive_time = 6.0}]  # further stages of "
                "the drive after the first at test.slip, each until steady (a slip ramp); keys: slip, drive_time [s], "
                "ramp_time [s]"]
    return []


def _version() -> str:
    from wheelsoil import __version__

    return __version__
