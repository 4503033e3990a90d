"""What a user relies on, gathered in one JSON-able dict: the names of scenarios, controllers,
maps, metrics, sweeps, report sections and claims; every scenario's config hash; every named
sweep's trial ids and config hashes (so stored results are still reused); ``teamnav list``'s
JSON; the metric registration order (it orders ``metrics.json``).

``tests/test_user_surface.py`` compares it with ``tests/data/user_surface.json``, recorded
before the papers moved into ``teamnav/papers/``. Record again only for a change that is
meant to change what users see: ``python tests/_user_surface.py > tests/data/user_surface.json``.
"""

from __future__ import annotations

import json
import sys


def gather() -> dict:
    from teamnav.cli import catalogue
    from teamnav.control import registry as controllers
    from teamnav.experiments import metrics
    from teamnav.experiments import registry as scenarios
    from teamnav.experiments.claims import load_claims
    from teamnav.experiments.report import available_sections
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep_spec import load_sweep, sweep_names
    from teamnav.experiments.sweep_trials import config_hash, expand

    out: dict = {
        "controllers": controllers.names(),
        "metrics": list(metrics.names()),
        "list_json": catalogue(),
        "scenario_hashes": {n: config_hash(load_scenario(n)) for n in scenarios.names()},
        "sweeps": {},
        "sections": sorted(k for k in available_sections()),
        "claims": {},
    }
    for name in sweep_names():
        out["sweeps"][name] = [[t.trial_id, t.config_hash] for t in expand(load_sweep(name))]
    for key in out["sections"]:
        try:
            out["claims"][key] = sorted(c.id for c in load_claims(key).claims)
        except Exception as exc:  # noqa: BLE001 - a section without a claim file
            out["claims"][key] = f"none: {type(exc).__name__}"
    return out


if __name__ == "__main__":
    json.dump(gather(), sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")
