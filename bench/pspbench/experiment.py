"""Experiment files (bench/experiments/*.toml): reading and checking them.

An experiment declares its cells (what is run: a sequence and how it is prepared), its variants
(how it is run: mode, flags, config keys, another build) and its base variant. The runner runs
every cell with every variant `repeats` times. The format is documented in
bench/experiments/README.md; every mistake is reported with the file and the field it is in.
"""
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

KINDS = ("slam", "segment", "gbench")
MODES = ("off", "semantic", "geometry", "full", "exhaustive")
METRICS = ("online", "final")
SYNTH_KEYS = {"frames": int, "bodies": int, "seed": int, "trajectory": str, "loop_turns": float,
              "sensor": str, "stereo": float, "layout": str, "depth_noise": str,
              "carried_objects": int, "occupancy_truth": float, "stand_seconds": float}


class ExperimentError(Exception):
    """A mistake in an experiment file; the message names the file and the field."""


@dataclass
class Stretch:
    """A part of a cell's frames evaluated on its own (aligned on its own ground truth)."""
    name: str
    first: int
    last: int | None


@dataclass
class Cell:
    name: str
    source: str  # "shared", "data", "synth", "images" or "program"
    location: str = ""  # folder under --shared or --data, or a program in the build
    synth: dict = field(default_factory=dict)
    config: str | None = None  # config file, relative to the repository
    config_set: dict = field(default_factory=dict)
    start: int = 0
    max_frames: int = 0
    reencode_jpeg: int = 0
    stretches: list = field(default_factory=list)
    split: str | None = None  # segment: JSON file of image ids, relative to the repository
    split_key: str = "val"
    args: list = field(default_factory=list)  # gbench: program arguments
    mode: str | None = None  # the cell's mode where a variant names none


@dataclass
class Variant:
    name: str
    mode: str | None = None
    flags: list = field(default_factory=list)
    config_set: dict = field(default_factory=dict)
    build: str | None = None
    env: dict = field(default_factory=dict)
    synth: dict = field(default_factory=dict)
    model: str | None = None  # segment: segmenter metadata YAML, relative to the repository
    busy_cores: int = 0  # competitor load: processes spinning beside the run (scripts/busy-cores)


@dataclass
class Experiment:
    path: Path
    name: str
    title: str
    description: str
    kind: str
    exclusive: bool
    repeats: int
    metric: str
    base: str
    mode: str  # the --dynamic mode of a run whose variant and cell name none
    spread_variant: str | None
    columns: dict
    keyframe_table: bool
    cells: list
    variants: list
    # The decision record (docs/decisions/NAME.md) whose evidence this experiment is: its tables
    # are regenerated there, not in docs/results.md, which holds the current figures only.
    record: str | None = None

    def needs_download(self):
        """Whether a cell reads downloaded sequences (--data): TUM, Bonn."""
        return any(cell.source == "data" for cell in self.cells)

    def mode_of(self, cell, variant):
        return variant.mode or cell.mode or self.mode


class Fields:
    """The fields of one TOML table, read with the path that names them in error messages."""

    def __init__(self, file, path, table):
        self.file, self.path, self.table = file, path, table
        self.read = set()

    def where(self, key):
        return f"{self.file}: {self.path + '.' if self.path else ''}{key}"

    def error(self, key, message):
        return ExperimentError(f"{self.where(key)}: {message}")

    def get(self, key, kind, default=None, required=False):
        self.read.add(key)
        if key not in self.table:
            if required:
                raise self.error(key, "missing (required)")
            return default
        value = self.table[key]
        if kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
            raise self.error(key, f"expected {_kind_name(kind)}, got {_describe(value)}")
        return value

    def get_list(self, key, item_kind, default=()):
        values = self.get(key, list, list(default))
        for index, value in enumerate(values):
            if not isinstance(value, item_kind) or isinstance(value, bool) != (item_kind is bool):
                raise self.error(f"{key}[{index}]",
                                 f"expected {_kind_name(item_kind)}, got {_describe(value)}")
        return values

    def get_choice(self, key, choices, default=None, required=False):
        value = self.get(key, str, default, required)
        if value is not None and value not in choices:
            raise self.error(key, f"'{value}' is not one of {', '.join(choices)}")
        return value

    def get_count(self, key, default, minimum=1):
        value = self.get(key, int, default)
        if value < minimum:
            raise self.error(key, f"must be at least {minimum}, got {value}")
        return value

    def sub(self, key, required=False):
        table = self.get(key, dict, None, required)
        return Fields(self.file, f"{self.path + '.' if self.path else ''}{key}", table or {})

    def reject_unknown(self):
        unknown = sorted(set(self.table) - self.read)
        if unknown:
            known = ", ".join(sorted(self.read))
            raise self.error(unknown[0], f"unknown field (known here: {known})")


def _kind_name(kind):
    return {str: "a string", int: "an integer", float: "a number", bool: "true or false",
            list: "a list", dict: "a table"}[kind]


def _describe(value):
    return f"{type(value).__name__} {value!r}"


def _config_settings(fields, key):
    """`set = { "camera.depth_factor" = 4999 }`: config keys (dotted YAML paths) and values."""
    settings = fields.get(key, dict, {})
    for name, value in settings.items():
        if not isinstance(value, (int, float, str, bool)):
            raise fields.error(f"{key}.{name}", f"expected a number, string or boolean, got "
                                                f"{_describe(value)}")
    return dict(settings)


def _synth_settings(fields, key):
    table = fields.sub(key)
    settings = {}
    for name, kind in SYNTH_KEYS.items():
        value = table.get(name, kind)
        if value is not None:
            settings[name] = value
    table.reject_unknown()
    return settings


def _read_stretches(fields):
    stretches = []
    for index, table in enumerate(fields.get("stretches", list, [])):
        if not isinstance(table, dict):
            raise fields.error(f"stretches[{index}]", f"expected a table, got {_describe(table)}")
        item = Fields(fields.file, f"{fields.path}.stretches[{index}]", table)
        stretch = Stretch(item.get("name", str, required=True), item.get_count("first", 0, 0),
                          item.get("last", int))
        if stretch.last is not None and stretch.last <= stretch.first:
            raise item.error("last", f"must be after first ({stretch.first}), got {stretch.last}")
        item.reject_unknown()
        stretches.append(stretch)
    return stretches


def _read_cells(fields, kind):
    tables = fields.get("cells", list, required=True)
    if not tables:
        raise fields.error("cells", "empty: an experiment needs at least one cell")
    cells = []
    for index, table in enumerate(tables):
        if not isinstance(table, dict):
            raise fields.error(f"cells[{index}]", f"expected a table, got {_describe(table)}")
        cells += _read_cell(Fields(fields.file, f"cells[{index}]", table), kind)
    names = [cell.name for cell in cells]
    for name in names:
        if names.count(name) > 1:
            raise fields.error("cells", f"two cells are named '{name}'")
    return cells


def _read_cell(fields, kind):
    """One [[cells]] table; a synthetic cell with `seeds = [...]` stands for one cell per seed."""
    name = fields.get("name", str, required=True)
    sources = {"shared": fields.get("shared", str), "data": fields.get("data", str),
               "program": fields.get("program", str)}
    synth = _synth_settings(fields, "synth") if "synth" in fields.table else None
    given = [key for key, value in sources.items() if value is not None]
    given += ["synth"] if synth is not None else []
    if len(given) != 1:
        raise fields.error("name", f"cell '{name}' needs exactly one of shared, data, synth, "
                                   f"program (has {', '.join(given) or 'none'})")
    source = given[0]
    if (source == "program") != (kind == "gbench"):
        raise fields.error(source, f"not allowed in a kind = \"{kind}\" experiment")
    cell = Cell(name=name, source=source, location=sources.get(source) or "", synth=synth or {},
                config=fields.get("config", str), config_set=_config_settings(fields, "set"),
                start=fields.get_count("start", 0, 0),
                max_frames=fields.get_count("max_frames", 0, 0),
                reencode_jpeg=fields.get_count("reencode_jpeg", 0, 0),
                stretches=_read_stretches(fields), split=fields.get("split", str),
                split_key=fields.get("split_key", str, "val"),
                args=fields.get_list("args", str), mode=fields.get_choice("mode", MODES))
    if cell.args and kind == "segment":
        raise fields.error("args", "not allowed in a kind = \"segment\" experiment")
    if cell.reencode_jpeg > 100:
        raise fields.error("reencode_jpeg", f"a JPEG quality is 1-100, got {cell.reencode_jpeg}")
    seeds = fields.get_list("seeds", int)
    fields.reject_unknown()
    if not seeds:
        return [cell]
    if source != "synth":
        raise fields.error("seeds", "only a synth cell has seeds")
    return [Cell(**{**cell.__dict__, "name": f"{name}_s{seed}",
                    "synth": {**cell.synth, "seed": seed}}) for seed in seeds]


def _read_variants(fields, modes):
    variants = [Variant(name=mode, mode=mode) for mode in modes]
    table = fields.sub("variants")
    for name in table.table:
        item = table.sub(name)
        variant = Variant(name=name, mode=item.get_choice("mode", MODES),
                          flags=item.get_list("flags", str),
                          config_set=_config_settings(item, "set"), build=item.get("build", str),
                          env={k: str(v) for k, v in item.get("env", dict, {}).items()},
                          synth=_synth_settings(item, "synth") if "synth" in item.table else {},
                          model=item.get("model", str),
                          busy_cores=item.get("busy_cores", int, 0))
        item.reject_unknown()
        if any(v.name == name for v in variants):
            raise table.error(name, f"variant '{name}' is also one of the modes")
        variants.append(variant)
    if not variants:
        variants.append(Variant(name="default"))
    return variants


def load(path):
    """Reads and checks an experiment file; raises ExperimentError naming the file and field."""
    path = Path(path)
    try:
        table = tomllib.loads(path.read_text())
    except OSError as error:
        raise ExperimentError(f"{path}: cannot read ({error.strerror})") from None
    except tomllib.TOMLDecodeError as error:
        raise ExperimentError(f"{path}: not valid TOML ({error})") from None
    fields = Fields(str(path), "", table)
    kind = fields.get_choice("kind", KINDS, "slam")
    modes = fields.get_list("modes", str)
    for index, mode in enumerate(modes):
        if mode not in MODES:
            raise fields.error(f"modes[{index}]", f"'{mode}' is not one of {', '.join(MODES)}")
    variants = _read_variants(fields, modes)
    names = [v.name for v in variants]
    default_base = names[0] if len(names) == 1 else None
    base = fields.get("base", str, default_base, required=default_base is None)
    if base not in names:
        raise fields.error("base", f"'{base}' is not a variant (variants: {', '.join(names)})")
    spread_variant = fields.get("spread_variant", str)
    if spread_variant is not None and spread_variant not in names:
        raise fields.error("spread_variant", f"'{spread_variant}' is not a variant "
                                             f"(variants: {', '.join(names)})")
    mode = fields.get_choice("mode", MODES, "full")
    columns = fields.get("columns", dict, {})
    for label, dotted in columns.items():
        if not isinstance(dotted, str):
            raise fields.error(f"columns.{label}", f"expected a dotted stats.json path, got "
                                                   f"{_describe(dotted)}")
    experiment = Experiment(
        path=path, name=path.stem, title=fields.get("title", str, required=True),
        description=fields.get("description", str, "").strip(), kind=kind,
        exclusive=fields.get("exclusive", bool, False), repeats=fields.get_count("repeats", 1),
        metric=fields.get_choice("metric", METRICS, "online"), base=base, mode=mode,
        spread_variant=spread_variant, columns=dict(columns),
        keyframe_table=fields.get("keyframe_table", bool, False), cells=_read_cells(fields, kind),
        variants=variants, record=fields.get("record", str))
    if experiment.record is not None and not (
            experiment.record.startswith("docs/decisions/") and experiment.record.endswith(".md")):
        raise fields.error("record", f"expected docs/decisions/NAME.md, got '{experiment.record}'")
    fields.reject_unknown()
    return experiment
