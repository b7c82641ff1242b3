"""The operator stack: every groom operator pelage has, in order, with all
its settings, in the panel, and groom files loaded into the panel and
saved from it.

An entry is an operator's name and one text field a setting, as the
groom file writes its value: a number, a list (`[0.3, 0.2, 0.1]`), or a
map (`vertex:GROUP`, `image.png:r`, `noise:frequency=8`;
docs/groom-format.md, "Maps"; and the add-on's `image:NAME:r` for a
Blender image, fur.py). An empty field takes pelage's default. The
operators and their settings come from the library
(`pelage._pelage.operator_schema()`), so an operator added to pelage
appears here without a change to the add-on.
"""

import json
import tomllib

def schema():
    """The library's operators: ``[{"name", "summary", "fields",
    "required"}]``, in the order pelage lists them."""
    from pelage import _pelage

    return _pelage.operator_schema()


def value_of(text):
    """A setting's text as a groom-file value: TOML (a number, a list, a
    quoted string), else the text itself (a map such as
    ``vertex:GROUP``)."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text.strip()


def text_of(value):
    """A groom-file value as the text ``value_of`` reads back."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, dict)):
        return json.dumps(value)
    return repr(value)


def add_entry(stack, kind, size=1.0, values=None):
    """Appends operator ``kind`` to ``stack`` (a collection of
    ``PelageOp``): one setting a field of the library's schema, with
    ``values`` (groom-file values by field), else where the library's
    schema starts each setting (so a new entry grows something visible;
    a start that is a length scaled by ``size``, the object's largest
    dimension). Returns the entry."""
    found = next((op for op in schema() if op["name"] == kind), None)
    if found is None:
        raise ValueError(f"pelage has no operator {kind!r}")
    entry = stack.add()
    entry.kind = kind
    declared = {s["name"]: s for s in found["settings"]}
    for field in found["fields"]:
        setting = entry.settings.add()
        setting.name = field
        if values is not None:
            value = values.get(field)
        else:
            setting_schema = declared.get(field, {})
            value = setting_schema.get("start")
            if value is not None and setting_schema.get("start_is_length"):
                value = value * size
        setting.value = "" if value is None else text_of(value)
    if values is not None:
        unknown = set(values) - set(found["fields"])
        if unknown:
            raise ValueError(f"{kind}: no setting {', '.join(sorted(unknown))}")
    return entry


def ops_of(stack):
    """The stack as the groom's ``ops``: each enabled entry's filled
    settings."""
    return [{op.kind: {s.name: value_of(s.value) for s in op.settings if s.value.strip()}}
            for op in stack if op.enabled]


def load_into(settings, path, size=1.0):
    """Fills the panel ``settings`` from the groom file at ``path``: the
    roots (count, seed), the finish (points, width), grown guides (count,
    length, gravity), the look, and the operator stack, replaced by the
    file's ``[[ops]]``. Returns what it left out (sections the panel has
    no place for), to report."""
    with open(path, "rb") as f:
        table = tomllib.load(f)
    left = []
    roots = table.get("roots", {})
    if "count" in roots:
        settings.count = int(roots["count"])
    if "seed" in roots:
        settings.seed = int(roots["seed"])
    finish = table.get("finish", {})
    if "points" in finish:
        settings.points = int(finish["points"])
    width = finish.get("width", {})
    if isinstance(width, dict) and isinstance(width.get("root"), (int, float)):
        settings.width = float(width["root"])
    generate = table.get("guides", {}).get("generate")
    if isinstance(generate, dict):
        for key in ("count", "length", "gravity"):
            value = generate.get(key)
            if isinstance(value, (int, float)):
                setattr(settings, "guides" if key == "count" else key, value)
    interpolation = table.get("interpolation", {})
    if interpolation.get("method") == "style-mesh":
        settings.interpolation = "STYLE_MESH"
    elif interpolation.get("method", "shepard") == "shepard":
        settings.interpolation = "SHEPARD"
        if isinstance(interpolation.get("k"), int):
            settings.interpolation_k = interpolation["k"]
    look = table.get("look", {})
    for key, name in (("melanin", "melanin"), ("melanin_redness", "melanin_redness"),
                      ("roughness", "roughness"), ("radial_roughness", "radial_roughness"),
                      ("jitter", "look_jitter")):
        if isinstance(look.get(key), (int, float)):
            setattr(settings, name, float(look[key]))
    density = roots.get("density")
    if isinstance(density, str) and density.startswith("vertex:"):
        settings.density_group = density[len("vertex:"):]
    faces = table.get("regions", {}).get("faces")
    parting = {"groups": "FACE_SETS", "materials": "MATERIALS"}.get(faces)
    if parting is not None:
        settings.parting = parting
    settings.ops.clear()
    for entry in table.get("ops", []):
        for kind, values in entry.items():
            add_entry(settings.ops, kind, size, values)
    settings.active_op = max(0, len(settings.ops) - 1)
    if "regions" in table and parting is None:
        left.append("[regions]")
    for section in ("animation", "simulation", "output"):
        if section in table:
            left.append(f"[{section}]")
    return left
