"""The generated ``beyond-*`` scenarios of sweep cases (Fox et al. §7.2's future work).

Each file must be exactly its sweep case: same resolved configuration (config hash), so
``teamnav run`` of the file reproduces a trial of the named sweep. (test_scenarios.py runs every
shipped scenario for 2 s.)
"""

from __future__ import annotations

import pytest

from teamnav.papers.beyond import case_scenarios as B


def test_shipped_files_are_what_the_generator_writes(tmp_path):
    from teamnav.experiments import registry

    for p in B.write_files(tmp_path):
        shipped = registry.path(p.stem)
        assert shipped.read_text(encoding="utf-8") == p.read_text(encoding="utf-8"), (
            f"{shipped.name} is stale: run python -m teamnav.papers.beyond.case_scenarios")


@pytest.mark.parametrize("item", B.CASE_SCENARIOS, ids=lambda i: i.name)
def test_each_scenario_is_its_sweep_case_and_differs_from_the_papers_case(item):
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep import config_hash, expand, load_sweep

    def without_metrics(scn):  # metrics observe only; the file adds EXTRA_METRICS to the sweep's set
        return config_hash(scn.model_copy(update={"metrics": ()}))

    spec = load_sweep(item.sweep)
    trials = expand(spec)
    by_case = {}
    for t in trials:
        params = {k: v for k, v in t.params.items() if k not in ("case", "duration_s")}
        by_case[t.params["case"]] = without_metrics(load_scenario(spec.scenario, overrides=params,
                                                                  duration_s=t.params.get("duration_s")))
    scn = load_scenario(item.name)
    assert set(load_scenario(spec.scenario, overrides=dict(spec.set)).metrics) <= set(scn.metrics)
    assert "path_length" in scn.metrics
    own = without_metrics(scn)
    assert own == by_case[item.case], f"{item.name} is not case {item.case!r} of sweep {item.sweep}"
    # the other case (the paper's rule) is a different configuration: the file pins the new rule
    others = {c for c, h in by_case.items() if c != item.case}
    assert others and all(by_case[c] != own for c in others)


def test_an_unknown_case_names_the_sweep_and_the_known_cases():
    bad = B.CaseScenario("beyond-x", "beyond-negative-detections-hallway", "maybe", "x")
    with pytest.raises(KeyError, match=r"beyond-negative-detections-hallway.*'maybe'.*\['off', 'on'\]"):
        B.scenario_data(bad)
