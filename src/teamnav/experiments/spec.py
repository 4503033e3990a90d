"""Scenario files: what to simulate, on which map, for how long, measuring what.

A scenario is a YAML file validated by :class:`Scenario`, which extends the simulator's
:class:`~teamnav.sim.config.SimConfig` (robots, sensors, odometry, radio, places, ``dt_s``,
``seed``) with::

    name: demo                        # used for the run folder name
    description: one line for `teamnav list`
    map:                              # exactly one of file / builtin / package / arena
      package: mit/basement_hallways_5cm.yaml   # a map shipped in teamnav/world/maps
      # file: maps/lab.yaml           # ROS map YAML or PNG/PGM, relative to this file's folder
      # builtin: trail_office         # a generated environment (teamnav.world.BUILTIN_MAPS)
      # arena: {width_m: 20, height_m: 20}      # an empty walled rectangle
      # resolution_m: 0.05            # cell size [m] (needed for a plain PNG/PGM file)
    duration_s: 60                    # simulated time [s]
    metrics: [path_length, collisions] # names from teamnav.experiments.metrics (default: all)
    give_map: false                   # robots get the map as prior knowledge (RobotInfo.known_map)
    stop_when_finished: false         # stop early once every brain with a `finished` flag is done

With a ``builtin`` map, named places of that environment can stand in for coordinates: a
``places`` entry ``{place: home, radius_m: 1.5, event: took_resource}`` takes its name and
position from the map's place ``home``, and a group's ``start: {near: home, spread_m: 1.0}``
becomes the square ``region`` of half-side ``spread_m`` around it; a moving place's waypoint
``{t_s: 600, place: c3_east_end}`` takes that place's position (``motion``:
:class:`~teamnav.sim.config.PlaceMotion`). All are replaced by plain
numbers when the scenario is validated, so the resolved scenario that a run writes needs no
map lookup to reproduce.

:func:`load_scenario` reads a file or a built-in scenario name, applies ``--set``
overrides, and raises :class:`~teamnav.experiments.errors.ScenarioError` (one clear message
naming the file and the field) for anything wrong, including the map and the controllers'
parameters, before any simulation starts.
"""

from __future__ import annotations

import copy
import difflib
import functools
import os
import re
from importlib import resources
from pathlib import Path
from typing import Any, ClassVar, Mapping, Sequence

import yaml
from pydantic import Field, PrivateAttr, ValidationError, field_validator, model_validator

from teamnav.control import registry as controllers
from teamnav.experiments import metrics as metric_registry
from teamnav.experiments import registry as scenarios
from teamnav.experiments.errors import (
    Problem,
    ScenarioError,
    YamlLimitError,
    from_validation_error,
    from_yaml_error,
    show_value,
)
from teamnav.sim.config import Model, SimConfig
from teamnav.safe_yaml import YAML_MAX_DEPTH, YAML_MAX_NODES, LimitedSafeLoader  # noqa: F401 (re-exported)
from teamnav.world.generators import BUILTIN_MAPS, MapBuilder
from teamnav.world.grid import OccupancyGrid
from teamnav.world.mapio import IMAGE_SUFFIXES, YAML_SUFFIXES, MapError, load_map, read_map_yaml

__all__ = [
    "ArenaSpec",
    "MAX_STEPS_PER_RUN",
    "MAX_STEPS_RAISED",
    "MapSpec",
    "PACKAGE_MAP_DIR",
    "Scenario",
    "apply_overrides",
    "build_grid",
    "canonical_key",
    "check_controllers",
    "load_scenario",
    "package_maps",
    "scenario_to_yaml",
]

#: Folder of the maps shipped with teamnav (``map: {package: ...}`` is relative to it).
PACKAGE_MAP_DIR: Path = Path(str(resources.files("teamnav.world"))) / "maps"

#: Most steps a run may take (``duration_s / dt_s``), 10^8: about 116 days of robot time at
#: the usual 0.1 s, and days of wall time for one robot. A scenario asking for more (a
#: ``dt_s`` of 1e-9 s, say) is refused when it is loaded, before anything is allocated, unless
#: it raises its own ceiling with ``max_steps: N`` (``--set max_steps=N``) to run that long on
#: purpose.
MAX_STEPS_PER_RUN: int = 100_000_000

#: The highest ``max_steps`` a scenario may give, 10^12: past it a run would not end in a
#: lifetime, whatever the machine.
MAX_STEPS_RAISED: int = 1_000_000_000_000

_MAP_SUFFIXES = YAML_SUFFIXES + IMAGE_SUFFIXES  # the map loader's (map_server YAML, PNG, PGM, BMP)

# the map memory limit lives with the grid (one definition for map files, images and arenas)
from teamnav.world.grid import MAP_BYTES_PER_CELL, MAX_MAP_BYTES, map_memory_problem  # noqa: E402,F401


def map_file_problem(path: str | os.PathLike) -> str | None:
    """Why the map file ``path`` (map YAML or image) is refused for its size, read from the
    image header only (None when it fits or cannot be read: :func:`load_map` then reports).

    Raises
    ------
    MapError
        The map YAML itself is invalid.
    """
    from PIL import Image

    path = Path(path)
    image = read_map_yaml(path).image if path.suffix.lower() in (".yaml", ".yml") else path
    try:
        with Image.open(image) as im:
            w, h = im.size
    except Image.DecompressionBombError as exc:
        return f"map image {image} is too large to open ({exc})"
    except Exception:  # noqa: BLE001 - unreadable images are load_map's to report, with its own message
        return None
    return map_memory_problem(w * h, f"map image {image} ({w} x {h} pixels)")


def _builtin_problem(name: str, resolution_m: float | None) -> str | None:
    """Why built-in map ``name`` at ``resolution_m`` is refused for its size (scaled from the
    cached default-resolution build, so nothing big is allocated)."""
    if resolution_m is None or name not in BUILTIN_MAPS:
        return None
    base = _builtin_env(name, None).grid
    cells = base.cells.size * (base.resolution_m / float(resolution_m)) ** 2
    return map_memory_problem(cells, f"built-in map {name!r} at resolution_m {resolution_m:g}")


class _YamlLoader(LimitedSafeLoader):
    """:class:`~teamnav.safe_yaml.LimitedSafeLoader` (no duplicate keys, bounded nesting and
    alias expansion) with YAML 1.2 booleans: only true/false, so ``on: enter`` (a PlaceConfig
    field) stays the key ``"on"`` instead of YAML 1.1's ``True``."""


_YamlLoader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_YamlLoader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)


def read_yaml(text: str):
    """Parse scenario YAML text (safe, YAML 1.2 booleans)."""
    return yaml.load(text, Loader=_YamlLoader)


def package_maps() -> list[str]:
    """Names usable as ``map: {package: NAME}``: every map file shipped in teamnav/world/maps."""
    out = []
    for p in sorted(PACKAGE_MAP_DIR.rglob("*")):
        if p.suffix.lower() in (".yaml", ".yml"):
            out.append(p.relative_to(PACKAGE_MAP_DIR).as_posix())
    return out


# ---------------------------------------------------------------------------- map spec
class ArenaSpec(Model):
    """An empty rectangle ``width_m`` x ``height_m`` enclosed by walls ``wall_thickness_m`` thick."""

    width_m: float = Field(20.0, gt=0.0, le=10_000.0)
    height_m: float = Field(20.0, gt=0.0, le=10_000.0)
    resolution_m: float = Field(0.05, gt=0.0, le=1.0)
    wall_thickness_m: float = Field(0.2, gt=0.0, le=100.0)

    @model_validator(mode="after")
    def _room_inside(self) -> "ArenaSpec":
        if min(self.width_m, self.height_m) <= 2 * self.wall_thickness_m:
            raise ValueError(
                f"arena must be wider and taller than two walls (2 x {self.wall_thickness_m} m), "
                f"got {self.width_m} x {self.height_m} m"
            )
        if max(self.width_m, self.height_m) / self.resolution_m > 20_000:
            raise ValueError(
                f"arena would need more than 20000 cells per side ({self.width_m} x {self.height_m} m "
                f"at {self.resolution_m} m); use a coarser resolution_m"
            )
        cells = round(self.width_m / self.resolution_m) * round(self.height_m / self.resolution_m)
        problem = map_memory_problem(cells, f"arena {self.width_m:g} x {self.height_m:g} m at {self.resolution_m:g} m")
        if problem:
            raise ValueError(problem)
        return self


class MapSpec(Model):
    """Where the map comes from: exactly one of ``file``, ``builtin``, ``package``, ``arena``.

    ``file``: a ROS map YAML or a plain PNG/PGM (then ``resolution_m`` is required); in a
    scenario file a relative path is relative to the scenario file's folder (load_scenario
    makes it absolute). ``builtin``: a generator of :data:`teamnav.world.BUILTIN_MAPS`
    (``resolution_m`` rebuilds it at another cell size). ``package``: a map shipped with
    teamnav, e.g. ``"nav2/depot.yaml"`` (``resolution_m`` replaces the file's). ``arena``: an
    empty walled rectangle.
    """

    file: str | None = Field(None, min_length=1)
    builtin: str | None = None
    package: str | None = None
    arena: ArenaSpec | None = None
    resolution_m: float | None = Field(None, gt=0.0, le=10.0)

    @model_validator(mode="after")
    def _exactly_one(self) -> "MapSpec":
        given = [k for k in ("file", "builtin", "package", "arena") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(
                "map: expected exactly one of 'file', 'builtin', 'package' or 'arena', "
                f"got {', '.join(repr(g) for g in given) if given else 'none'}"
            )
        if self.builtin is not None and self.builtin not in BUILTIN_MAPS:
            close = difflib.get_close_matches(self.builtin, BUILTIN_MAPS, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ValueError(
                f"map.builtin: unknown built-in map {self.builtin!r}{hint} (known: {', '.join(sorted(BUILTIN_MAPS))})"
            )
        if self.builtin is not None:
            problem = _builtin_problem(self.builtin, self.resolution_m)
            if problem:
                raise ValueError(f"map.resolution_m: {problem}")
        if self.package is not None:
            known = package_maps()
            target = PACKAGE_MAP_DIR / self.package
            if ".." in Path(self.package).parts or not target.is_file():
                close = difflib.get_close_matches(self.package, known, n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ValueError(f"map.package: unknown packaged map {self.package!r}{hint} (known: {', '.join(known)})")
        if self.file is not None:
            p = Path(self.file)
            if p.suffix.lower() not in _MAP_SUFFIXES:
                raise ValueError(f"map.file: expected a file ending in one of {', '.join(_MAP_SUFFIXES)}, got {self.file!r}")
            if not p.is_file():
                raise ValueError(f"map.file: expected an existing map file, got {self.file!r} (no such file)")
            if p.suffix.lower() in IMAGE_SUFFIXES and self.resolution_m is None:
                raise ValueError(f"map.resolution_m: a plain image map ({self.file!r}) needs resolution_m [m per pixel]")
        if self.arena is not None and self.resolution_m is not None:
            raise ValueError("map.resolution_m: an arena has its own 'arena.resolution_m'; remove map.resolution_m")
        return self

    def describe(self) -> str:
        """One line: where the map comes from."""
        if self.arena is not None:
            return f"arena {self.arena.width_m:g} x {self.arena.height_m:g} m"
        kind = next(k for k in ("file", "builtin", "package") if getattr(self, k) is not None)
        return f"{kind}:{getattr(self, kind)}"


# ---------------------------------------------------------------------------- scenario
def _named_waypoints(place: Any) -> bool:
    """Whether a raw ``places`` entry has a moving ``motion.path`` waypoint given by name
    (``{t_s: 600, place: c3_east_end}``: a built-in map's place stands in for ``x_m``/``y_m``)."""
    motion = place.get("motion") if isinstance(place, dict) else None
    path = motion.get("path") if isinstance(motion, dict) else None
    return isinstance(path, (list, tuple)) and any(isinstance(w, dict) and "place" in w for w in path)


class Scenario(SimConfig):
    """A complete experiment: the simulation (:class:`SimConfig`) plus map, duration, metrics.

    Attributes
    ----------
    name : str
        Short name (letters, digits, ``-_.``), used for the default run folder.
    description : str
        What the scenario shows; its first line is listed by ``teamnav list``.
    map : MapSpec
    duration_s : float
        Simulated time [s], in (0, 1e7] and at least ``dt_s``; the run takes
        ``round(duration_s / dt_s)`` steps, at most :data:`MAX_STEPS_PER_RUN` (or ``max_steps``).
    metrics : tuple of str
        Metric names (:func:`teamnav.experiments.metrics.names`); empty means all.
    give_map : bool
        Robots receive the map as prior knowledge (``RobotInfo.known_map``), default False.
    stop_when_finished : bool
        End the run before ``duration_s`` once every brain that reports ``finished`` (a
        controller attribute: its task is done, e.g. R1 reached its last target) says so;
        ``duration_s`` is then the step budget. Default False.
    max_steps : int, optional
        The most steps this scenario may take, in place of :data:`MAX_STEPS_PER_RUN`, up to
        :data:`MAX_STEPS_RAISED`; for a run meant to be that long. Left out of the resolved
        scenario when absent (config hashes unchanged).
    """

    name: str = Field(min_length=1, max_length=100, pattern=r"^[A-Za-z0-9][A-Za-z0-9_.\-]*$")
    description: str = ""
    map: MapSpec
    duration_s: float = Field(60.0, gt=0.0, le=1e7)
    metrics: tuple[str, ...] = ()
    give_map: bool = False
    stop_when_finished: bool = False
    #: settings for :mod:`teamnav.env` (agents, rewards, observations), validated there;
    #: ``teamnav run`` ignores them, so one file serves both. Left out of the resolved scenario
    #: when absent (config hashes of scenarios without it are unchanged).
    env: dict[str, Any] | None = None
    max_steps: int | None = Field(None, ge=1, le=MAX_STEPS_RAISED)
    _OMIT_WHEN_NONE: ClassVar[tuple[str, ...]] = ("env", "max_steps")

    _source: str = PrivateAttr(default="<code>")

    @model_validator(mode="before")
    @classmethod
    def _named_places(cls, data: Any) -> Any:
        """Replace ``place:`` / ``start.near`` references by coordinates of the built-in map."""
        if not isinstance(data, dict):
            return data
        places, robots = data.get("places"), data.get("robots")
        places = places if isinstance(places, (list, tuple)) else ()  # anything else is the field validators' to report
        robots = robots if isinstance(robots, (list, tuple)) else ()
        uses_places = any(isinstance(p, dict) and ("place" in p or _named_waypoints(p)) for p in places) or any(
            isinstance(g, dict) and isinstance(g.get("start"), dict) and "near" in g["start"] for g in robots
        )
        if not uses_places:
            return data
        spec = data.get("map")
        builtin = spec.get("builtin") if isinstance(spec, dict) else None
        if not isinstance(builtin, str) or builtin not in BUILTIN_MAPS:
            raise ValueError(
                "places given by name ('place:' or 'start.near:') need 'map: {builtin: NAME}' naming a built-in "
                f"map, got map {show_value(spec)}"
            )
        res = spec.get("resolution_m")
        res = res if isinstance(res, (int, float)) and not isinstance(res, bool) and 0 < res <= 10 else None
        problem = _builtin_problem(builtin, res)
        if problem:
            raise ValueError(f"map.resolution_m: {problem}")
        named = _builtin_env(builtin, res).places
        data = copy.deepcopy(data)

        def where(field: str, ref: Any) -> tuple[float, float]:
            if not isinstance(ref, str):
                raise ValueError(f"{field}: expected the name of a place of built-in map {builtin!r}, got {show_value(ref)}")
            if ref not in named:
                close = difflib.get_close_matches(str(ref), named, n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ValueError(
                    f"{field}: unknown place {show_value(ref)} of built-in map {builtin!r}{hint} (known: {', '.join(named)})"
                )
            return named[ref]

        def located(d: dict, field: str) -> tuple[dict, Any]:
            """``d`` with its ``place`` key turned into ``x_m``, ``y_m`` (a copy), and the name."""
            d = dict(d)
            ref = d.pop("place")
            if "x_m" in d or "y_m" in d:
                raise ValueError(f"{field}: give either 'place' or 'x_m'/'y_m', not both")
            d["x_m"], d["y_m"] = where(f"{field}.place", ref)
            return d, ref

        if isinstance(data.get("places"), (list, tuple)):
            places = []
            for i, p in enumerate(data["places"]):
                if isinstance(p, dict) and "place" in p:
                    p, ref = located(p, f"places[{i}]")
                    p.setdefault("name", ref)
                if isinstance(p, dict) and _named_waypoints(p):
                    p = dict(p)
                    p["motion"] = motion = dict(p["motion"])
                    motion["path"] = [located(w, f"places[{i}].motion.path[{j}]")[0]
                                      if isinstance(w, dict) and "place" in w else w
                                      for j, w in enumerate(motion["path"])]
                places.append(p)
            data["places"] = places
        if isinstance(data.get("robots"), (list, tuple)):
            robots = []
            for i, g in enumerate(data["robots"]):
                start = g.get("start") if isinstance(g, dict) else None
                if isinstance(start, dict) and "near" in start:
                    start = dict(start)
                    x, y = where(f"robots[{i}].start.near", start.pop("near"))
                    spread = start.pop("spread_m", 1.0)
                    if not isinstance(spread, (int, float)) or not (0 < spread < 1e6):
                        raise ValueError(f"robots[{i}].start.spread_m: expected a positive number of metres, got {show_value(spread)}")
                    if "region" in start or "poses" in start:
                        raise ValueError(f"robots[{i}].start: give 'near' or 'region'/'poses', not both")
                    start["region"] = [x - spread, x + spread, y - spread, y + spread]
                    g = {**g, "start": start}
                robots.append(g)
            data["robots"] = robots
        return data

    @model_validator(mode="after")
    def _steps_fit(self) -> "Scenario":
        """``dt_s`` no longer than ``duration_s``, and no more steps than the limit (counted, not made)."""
        if self.dt_s > self.duration_s:
            raise ValueError(
                f"dt_s: expected a time step no longer than duration_s ({self.duration_s:g} s), got {self.dt_s:g} s "
                f"(a run is whole steps, so it would simulate {self.dt_s:g} s); shorten dt_s or lengthen duration_s"
            )
        steps = self.duration_s / self.dt_s
        limit = self.max_steps if self.max_steps is not None else MAX_STEPS_PER_RUN
        if round(steps) > limit:
            which = "max_steps" if self.max_steps is not None else "teamnav.experiments.spec.MAX_STEPS_PER_RUN"
            raise ValueError(
                f"dt_s: duration_s {self.duration_s:g} s in steps of {self.dt_s:g} s is {steps:.3g} steps; expected at "
                f"most {limit:,} ({which}); lengthen dt_s or shorten duration_s, or set max_steps (up to "
                f"{MAX_STEPS_RAISED:,}) to run that many on purpose"
            )
        return self

    @field_validator("metrics")
    @classmethod
    def _known_metrics(cls, v: tuple[str, ...]) -> tuple[str, ...]:
        known = metric_registry.names()
        for m in v:
            if m not in known:
                close = difflib.get_close_matches(m, known, n=1)
                hint = f"; did you mean {close[0]!r}?" if close else ""
                raise ValueError(f"unknown metric {m!r}{hint} (known: {', '.join(known)})")
        if len(set(v)) != len(v):
            raise ValueError(f"metrics are listed twice: {sorted({m for m in v if v.count(m) > 1})}")
        return v

    @property
    def source(self) -> str:
        """The file this scenario was loaded from (``"<code>"`` when built in Python)."""
        return self._source

    @property
    def n_steps(self) -> int:
        """Steps a run takes: ``round(duration_s / dt_s)``, at least 1."""
        return max(1, int(round(self.duration_s / self.dt_s)))

    @property
    def metric_names(self) -> tuple[str, ...]:
        """The metrics to compute: ``metrics``, or every registered metric when empty."""
        return self.metrics or tuple(metric_registry.names())


# ---------------------------------------------------------------------------- maps
@functools.lru_cache(maxsize=16)
def _builtin_env(name: str, resolution_m: float | None):
    factory = BUILTIN_MAPS[name]
    return factory() if resolution_m is None else factory(resolution_m)


@functools.lru_cache(maxsize=16)
def _file_grid(path: str, mtime_ns: int, resolution_m: float | None) -> OccupancyGrid:
    return load_map(path, resolution_m=resolution_m)


@functools.lru_cache(maxsize=16)
def _file_problem(path: str, mtime_ns: int) -> str | None:
    return map_file_problem(path)


@functools.lru_cache(maxsize=8)
def _arena_grid(arena: ArenaSpec) -> OccupancyGrid:
    b = MapBuilder(arena.width_m, arena.height_m, arena.resolution_m)
    b.border(arena.wall_thickness_m)
    return b.build(f"arena:{arena.width_m:g}x{arena.height_m:g}")


def build_grid(scenario: Scenario) -> OccupancyGrid:
    """The scenario's map as an :class:`OccupancyGrid` (cached: grids are immutable).

    Raises
    ------
    ScenarioError
        Naming the scenario file and ``map.*`` when the map cannot be read (the map
        loader's own message, which names the map file and its field, is kept).
    """
    spec = scenario.map
    try:
        if spec.arena is not None:
            return _arena_grid(spec.arena)
        if spec.builtin is not None:
            return _builtin_env(spec.builtin, spec.resolution_m).grid
        path = Path(spec.file) if spec.file is not None else PACKAGE_MAP_DIR / str(spec.package)
        field = "map.file" if spec.file is not None else "map.package"
        try:
            mtime = path.stat().st_mtime_ns
        except OSError:
            raise ScenarioError.one(scenario.source, field, "expected an existing map file", f"{path} (no such file)", raw=True)
        problem = _file_problem(str(path), mtime)
        if problem:
            raise ScenarioError(scenario.source, [Problem(field, problem)])
        return _file_grid(str(path), mtime, spec.resolution_m)
    except MapError as exc:
        field = "map.file" if spec.file is not None else "map.package"
        raise ScenarioError(scenario.source, [Problem(field, f"the map is invalid: {exc}")]) from None
    except ValueError as exc:  # a generator refusing a resolution
        if isinstance(exc, ScenarioError):
            raise
        raise ScenarioError(scenario.source, [Problem("map.resolution_m", str(exc))]) from None


# ---------------------------------------------------------------------------- booleans as numbers
def bool_number_problems(model: Any, raw: Any, prefix: str = "") -> list[Problem]:
    """Fields where the file gave ``true``/``false`` but the model made a number of it.

    pydantic's lax mode reads ``count: true`` as 1; a count, a seed or a length given as a
    boolean is a mistake, so every such field is reported (walking the validated ``model``
    beside the ``raw`` data it came from, nested models and lists included).
    """
    from pydantic import BaseModel

    problems: list[Problem] = []

    def check(value: Any, given: Any, path: str) -> None:
        if isinstance(given, bool) and isinstance(value, (int, float)) and not isinstance(value, bool):
            kind = "an integer" if isinstance(value, int) else "a number"
            problems.append(Problem(path, f"expected {kind}, not a boolean", show_value(given).lower()))
        elif isinstance(value, BaseModel) and isinstance(given, dict):
            for name, info in type(value).model_fields.items():
                key = info.alias or name
                if key in given:
                    check(getattr(value, name), given[key], f"{path}.{key}" if path else key)
        elif isinstance(value, (list, tuple)) and isinstance(given, (list, tuple)) and len(value) == len(given):
            for i, (v, g) in enumerate(zip(value, given)):
                check(v, g, f"{path}[{i}]")
        elif isinstance(value, dict) and isinstance(given, dict):
            for k, v in value.items():
                if k in given:
                    check(v, given[k], f"{path}.{k}" if path else str(k))

    check(model, raw, prefix)
    return problems


def _note_for(field: str, notes: Mapping[str, str]) -> str | None:
    """The override note (``from --set ...``) of ``field`` or of the nearest field above it."""
    keys = [key for key in notes if field == key or field.startswith((key + ".", key + "["))]
    return notes[max(keys, key=len)] if keys else None


# ---------------------------------------------------------------------------- controllers
def check_controllers(scenario: Scenario) -> list[Problem]:
    """Problems with the robot groups' controllers: unknown names, invalid ``params``.

    Each group's ``params`` are validated by its controller's ``Params`` model, so a typo in
    a controller parameter stops the run before it starts and names ``robots[i].params.KEY``.
    """
    problems: list[Problem] = []
    for i, group in enumerate(scenario.robots):
        try:
            cls = controllers.lookup(group.controller)
        except KeyError as exc:
            problems.append(Problem(f"robots[{i}].controller", str(exc.args[0])))
            continue
        params_model = getattr(cls, "Params", None)
        if params_model is None:
            continue
        try:
            params = params_model.model_validate(group.params)
        except ValidationError as exc:
            err = from_validation_error(exc, scenario.source, group.params, model=params_model, prefix=f"robots[{i}].params")
            problems.extend(err.problems)
        else:
            problems.extend(bool_number_problems(params, group.params, f"robots[{i}].params"))
    return problems


# ---------------------------------------------------------------------------- overrides
def _pretty(parts: Sequence[str]) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if p.isdigit() else (f".{p}" if out else p)
    return out


def canonical_key(key: str) -> str:
    """The one spelling of a dotted override key, as :func:`apply_overrides` reads it.

    :func:`apply_overrides` takes a key with blanks around it (``" robots.0.count"``) and reads
    a part made of decimal digits as a list index by its value, so ``robots.00.count``,
    ``robots.\u0660.count`` (an Arabic-Indic zero) and ``robots.\uff10.count`` (a full-width
    zero) all set ``robots[0].count``. This returns that key once: stripped, every all-digit
    part written as a plain ASCII number without leading zeros. Sweeps compare and store keys
    in this spelling, so two spellings of one field are seen as the same key. Anything else
    (an empty part, blanks inside a part, brackets) is returned as it is, for the caller's
    checks to refuse.

    >>> canonical_key(" robots.007.count"), canonical_key("radio.p_loss")
    ('robots.7.count', 'radio.p_loss')
    """
    parts = str(key).strip().split(".")
    return ".".join(str(int(p)) if p.isdecimal() else p for p in parts)


def apply_overrides(data: dict, overrides: Mapping[str, Any] | Sequence[str] | None, file: str = "<scenario>") -> dict[str, str]:
    """Set dotted-path overrides in the raw scenario ``data`` (in place).

    Parameters
    ----------
    data : dict
        The scenario as read from YAML.
    overrides : dict of str to value, or list of "key=value" strings, or None
        ``"robots.0.count=10"``, ``"radio.p_loss=0.1"``: dotted keys, integers index lists
        (read as :func:`canonical_key` writes them: ``robots.00.count`` is ``robots.0.count``);
        string values of ``"key=value"`` items are parsed as YAML (``0.1``, ``true``, ``[1, 2]``).
    file : str
        The scenario file, for messages.

    Returns
    -------
    dict of str to str
        Field path (``robots[0].count``) to a note (``"from --set robots.0.count=10"``), so
        validation errors can say which override caused them.

    Raises
    ------
    ScenarioError
        A malformed item, a value that is not YAML, or a path through a missing list item
        or a non-mapping.
    """
    notes: dict[str, str] = {}
    if overrides is None:
        return notes
    if isinstance(overrides, Mapping):
        items = [(str(k), v, f"{k}={v!r}") for k, v in overrides.items()]
    else:
        items = []
        for item in overrides:
            if not isinstance(item, str) or "=" not in item:
                raise ScenarioError.one(file, "--set", "expected KEY=VALUE (e.g. radio.p_loss=0.1)", item)
            key, _, text = item.partition("=")
            key = key.strip()
            try:
                value = read_yaml(text) if text.strip() else None
            except yaml.YAMLError as exc:
                first = str(exc).splitlines()[0]
                raise ScenarioError.one(file, f"--set {key}", f"expected a YAML value ({first})", text) from None
            items.append((key, value, item))
    for key, value, shown in items:
        # a copy: a later dotted key writes into what this one set, never into the caller's object
        # (a sweep's `set` dict shared by all its cases leaked one case's value into every case)
        value = copy.deepcopy(value)
        parts = canonical_key(key).split(".")
        if not key or any(not p for p in parts):
            raise ScenarioError.one(file, "--set", "expected a dotted key such as robots.0.count", key)
        node: Any = data
        for depth, part in enumerate(parts):
            last = depth == len(parts) - 1
            here = _pretty(parts[: depth + 1])
            if isinstance(node, list):
                if not part.isdecimal() or int(part) >= len(node):
                    raise ScenarioError.one(
                        file,
                        f"--set {key}",
                        f"{_pretty(parts[:depth])} is a list of {len(node)} item(s); expected an index "
                        f"0..{len(node) - 1}",
                        part,
                    )
                if last:
                    node[int(part)] = value
                else:
                    node = node[int(part)]
            elif isinstance(node, dict):
                if last:
                    node[part] = value
                elif part in node and node[part] is not None:
                    node = node[part]
                elif parts[depth + 1].isdecimal():
                    raise ScenarioError.one(
                        file,
                        f"--set {key}",
                        f"{here} is not written out in the scenario, so item {parts[depth + 1]} cannot be set; "
                        f"write the list in the file first",
                        None,
                    )
                else:
                    node[part] = {}
                    node = node[part]
            else:
                raise ScenarioError.one(file, f"--set {key}", f"{_pretty(parts[:depth])} is not a mapping or list", node)
        notes[_pretty(parts)] = f"from --set {shown}"
    return notes


# ---------------------------------------------------------------------------- loading
def _looks_like_path(s: str) -> bool:
    return s.lower().endswith((".yaml", ".yml")) or "/" in s or os.sep in s or Path(s).exists()


def _read_yaml(path: Path) -> dict:
    file = str(path)
    if path.is_dir():
        raise ScenarioError.one(file, "", "expected a scenario YAML file", "a directory", raw=True)
    if not path.is_file():
        raise ScenarioError.one(file, "", "expected an existing scenario file", "no such file", raw=True)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError.one(file, "", "expected a readable UTF-8 text file", str(exc), raw=True) from None
    try:
        data = read_yaml(text)
    except yaml.YAMLError as exc:
        raise from_yaml_error(exc, file) from None
    except RecursionError:  # the loader bounds nesting; this is a last guard
        raise ScenarioError.one(file, "", f"expected at most {YAML_MAX_DEPTH} levels of nesting", "a document nested too deeply", raw=True) from None
    if data is None:
        raise ScenarioError.one(file, "", "expected a mapping of scenario fields, the file is empty")
    if not isinstance(data, dict):
        raise ScenarioError.one(file, "", "expected a mapping of scenario fields at the top level", type(data).__name__, raw=True)
    bad = [k for k in data if not isinstance(k, str)]
    if bad:
        raise ScenarioError.one(file, "", "expected field names to be strings", bad[0])
    return data


def load_scenario(
    name_or_path: str | os.PathLike | Scenario,
    *,
    overrides: Mapping[str, Any] | Sequence[str] | None = None,
    seed: int | None = None,
    duration_s: float | None = None,
) -> Scenario:
    """Load, override and fully validate a scenario.

    Parameters
    ----------
    name_or_path : str, Path or Scenario
        A built-in scenario name (``"demo"``; see :func:`teamnav.experiments.registry.names`),
        a YAML file, or a :class:`Scenario` to override.
    overrides : dict or list of "key=value", optional
        Dotted-path overrides (see :func:`apply_overrides`), applied before validation.
    seed : int, optional
        Replaces ``seed``.
    duration_s : float, optional
        Replaces ``duration_s``.

    Returns
    -------
    Scenario
        Validated, with ``map.file`` made absolute, named places resolved, every controller's
        ``params`` checked and the map loaded once (so a broken map fails here).

    Raises
    ------
    ScenarioError
        Anything wrong, in one message naming the file and the field.

    Examples
    --------
    >>> s = load_scenario("demo", overrides=["robots.0.count=2"], seed=3, duration_s=5)
    >>> s.robots[0].count, s.seed, s.duration_s
    (2, 3, 5.0)
    """
    if isinstance(name_or_path, Scenario):
        file = name_or_path.source
        data = name_or_path.model_dump(mode="json")
        base = None
    else:
        text = os.fspath(name_or_path)
        if _looks_like_path(text):
            path = Path(text)
        else:
            try:
                path = scenarios.path(text)
            except KeyError as exc:
                raise ScenarioError.one(f"<name {text!r}>", "", str(exc.args[0])) from None
        file = str(path)
        data = _read_yaml(path)
        base = path.resolve().parent
        data.setdefault("name", path.stem if path.stem[:1].isalnum() else "scenario")
    data = copy.deepcopy(data)
    file_before = data.get("map", {}).get("file") if isinstance(data.get("map"), dict) else None
    notes = apply_overrides(data, overrides, file)
    if seed is not None:
        data["seed"] = seed
        notes["seed"] = "from --seed"
    if duration_s is not None:
        data["duration_s"] = duration_s
        notes["duration_s"] = "from --duration"
    spec = data.get("map")
    if base is not None and isinstance(spec, dict) and isinstance(spec.get("file"), str) and spec["file"]:
        p = Path(os.path.expanduser(spec["file"]))
        # a map file named in the scenario file is relative to that file's folder; one given
        # with --set (the scenario may be a built-in one) is relative to where teamnav runs
        here = base if spec["file"] == file_before else Path.cwd()
        spec["file"] = str(p if p.is_absolute() else (here / p))
    try:
        scn = Scenario.model_validate(data)
    except ValidationError as exc:
        raise from_validation_error(exc, file, data, model=Scenario, notes=notes) from None
    except RecursionError:  # a Python dict nested past the interpreter's limit (files are bounded by the loader)
        raise ScenarioError.one(file, "", "expected a scenario nested at most a few levels deep", "a structure nested too deeply", raw=True) from None
    scn._source = file
    problems = [Problem(p.field, p.message, p.received, _note_for(p.field, notes)) for p in bool_number_problems(scn, data)]
    problems += check_controllers(scn)
    if problems:
        raise ScenarioError(file, problems)
    build_grid(scn)
    return scn


def scenario_to_yaml(scenario: Scenario) -> str:
    """The resolved scenario as YAML text that :func:`load_scenario` reads back to an equal one."""
    return yaml.safe_dump(scenario.model_dump(mode="json"), sort_keys=False, allow_unicode=True)
