"""Controllers found by name, so a scenario file can name them (STYLE habit 9).

Entries are versioned names mapped to lazy ``"module:attr"`` entry points, as Gymnasium's
registry does. Unknown names get a "did you mean" hint; a second registration of a name
raises.
"""

from __future__ import annotations

import difflib
import importlib
from typing import Any

_REGISTRY: dict[str, str] = {}


def register(name: str, entry_point: str) -> None:
    """Register controller ``name`` (e.g. ``"wander-v1"``) at ``"package.module:Class"``."""
    if name in _REGISTRY:
        raise ValueError(f"controller {name!r} is already registered (at {_REGISTRY[name]})")
    if ":" not in entry_point:
        raise ValueError(f"entry point for {name!r} must look like 'module:attr', got {entry_point!r}")
    _REGISTRY[name] = entry_point


def names() -> list[str]:
    """All registered controller names, sorted."""
    return sorted(_REGISTRY)


def lookup(name: str) -> Any:
    """The controller class registered as ``name``.

    Raises
    ------
    KeyError
        With a "did you mean" hint when ``name`` is unknown.
    """
    try:
        entry = _REGISTRY[name]
    except KeyError:
        close = difflib.get_close_matches(name, _REGISTRY, n=3)
        hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        raise KeyError(f"unknown controller {name!r}{hint} (known: {', '.join(names())})") from None
    module, attr = entry.split(":")
    return getattr(importlib.import_module(module), attr)


# Built-in controllers. Paper systems add theirs here as they land.
register("idle-v1", "teamnav.control.idle:Idle")
register("wander-v1", "teamnav.control.nav.wander:Wander")
register("wander-batched-v1", "teamnav.control.nav.wander:WanderBatched")

# Trail experiments baseline (Vaughan et al.; helper H7): the single optimal robot
register("route-follow-v1", "teamnav.control.nav.route_follow:RouteFollow")

# Fox, Burgard, Kruppa & Thrun: collaborative multi-robot MCL (helper H5)
register("mcl-wander-v1", "teamnav.control.localizing:MCLWander")

# Vaughan et al. trail papers: low-level Navigate + Panic, random exploration (helper H3)
register("explore-v1", "teamnav.control.nav.explore:Explore")

# Sgorbissa & Arkin: line-of-sight help, R1 explorer and patrolling helpers (helper H2)
register("los-explorer-v1", "teamnav.control.coop.los_help.explorer:LosExplorer")
register("los-helper-v1", "teamnav.control.coop.los_help.helper:LosHelper")

# Vaughan et al. trail papers: Blazing a trail (2000) and Try to see it my way (2002) (helper H4)
register("blazing-trail-v1", "teamnav.control.coop.blazing_trail:BlazingTrail")
register("trail-share-v1", "teamnav.control.coop.trail_share:TrailShare")
