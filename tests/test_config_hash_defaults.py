"""A trial's configuration hash covers its brains' parameters as they resolve, defaults included.

Scenarios name only the brain parameters they change; the rest are the brain's defaults, part of
teamnav's code. A stored trial made before a default changed must not be taken for the same
configuration (a results folder reused across such a change would otherwise serve stale rows:
the trail brains' crumb and recovery radii were re-chosen as defaults on 2026-11-29).
"""

from __future__ import annotations

from pydantic import BaseModel

from teamnav.control import registry
from teamnav.experiments.spec import load_scenario
from teamnav.experiments.sweep import config_hash


def test_spelling_out_a_default_is_the_same_configuration():
    plain = load_scenario("blazing-a-trail")
    cls = registry.lookup(plain.robots[0].controller)
    default = cls.Params().recover_radius_m
    spelled = load_scenario("blazing-a-trail", overrides={"robots.0.params.recover_radius_m": default})
    assert config_hash(plain) == config_hash(spelled)
    other = load_scenario("blazing-a-trail", overrides={"robots.0.params.recover_radius_m": default + 1.0})
    assert config_hash(plain) != config_hash(other)


def test_a_changed_default_is_another_configuration(monkeypatch):
    scenario = load_scenario("blazing-a-trail")
    before = config_hash(scenario)
    real = registry.lookup(scenario.robots[0].controller)
    default = real.Params().recover_radius_m

    class Changed(real.Params):  # the same brain, one default moved
        recover_radius_m: float = default + 3.0

    class Brain:
        Params = Changed

    name = scenario.robots[0].controller
    monkeypatch.setattr(registry, "lookup", lambda n: Brain if n == name else real)
    assert config_hash(scenario) != before


def test_an_unresolvable_controller_still_hashes(monkeypatch):
    scenario = load_scenario("blazing-a-trail")

    def missing(name):
        raise KeyError(f"unknown controller {name!r}")

    monkeypatch.setattr(registry, "lookup", missing)
    assert len(config_hash(scenario)) == 16  # the group's own params stand in; the run names the problem

    class Strict(BaseModel):
        needed: int

    class Brain:
        Params = Strict

    monkeypatch.setattr(registry, "lookup", lambda name: Brain)
    assert len(config_hash(scenario)) == 16
