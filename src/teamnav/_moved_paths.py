"""Import paths that moved when each paper got its folder (``teamnav/papers/<paper>/``).

Kept for one release: ``import teamnav.control.coop.los_help`` (and every other old path
below) still works, gives the module at its new path, and warns with a
:class:`DeprecationWarning` naming that path. :func:`install` puts the finder on
``sys.meta_path``; :mod:`teamnav` calls it on import.

This table is the one core module that names papers' modules; the core never imports them
(``tests/test_import_boundary.py`` exempts this file by name).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

__all__ = ["MOVED", "install"]

#: old module path -> new module path
MOVED: dict[str, str] = {
    'teamnav.control.anonymous_association': 'teamnav.papers.collab_mcl.brains.anonymous_association',
    'teamnav.control.beyond': 'teamnav.papers.beyond.brains',
    'teamnav.control.beyond.detecting': 'teamnav.papers.beyond.brains.detecting',
    'teamnav.control.beyond.localized': 'teamnav.papers.beyond.brains.localized',
    'teamnav.control.beyond.localized_los': 'teamnav.papers.beyond.brains.localized_los',
    'teamnav.control.beyond.trail_memory': 'teamnav.papers.beyond.brains.trail_memory',
    'teamnav.control.coop.blazing_trail': 'teamnav.papers.trails.brains.blazing_trail',
    'teamnav.control.coop.crumbs': 'teamnav.papers.trails.brains.crumbs',
    'teamnav.control.coop.forager': 'teamnav.papers.trails.brains.forager',
    'teamnav.control.coop.los_help': 'teamnav.papers.los_help.brains',
    'teamnav.control.coop.los_help.brain': 'teamnav.papers.los_help.brains.brain',
    'teamnav.control.coop.los_help.driving': 'teamnav.papers.los_help.brains.driving',
    'teamnav.control.coop.los_help.explorer': 'teamnav.papers.los_help.brains.explorer',
    'teamnav.control.coop.los_help.explorer_params': 'teamnav.papers.los_help.brains.explorer_params',
    'teamnav.control.coop.los_help.goal_sharing': 'teamnav.papers.los_help.brains.goal_sharing',
    'teamnav.control.coop.los_help.helper': 'teamnav.papers.los_help.brains.helper',
    'teamnav.control.coop.los_help.messages': 'teamnav.papers.los_help.brains.messages',
    'teamnav.control.coop.los_help.params': 'teamnav.papers.los_help.brains.params',
    'teamnav.control.coop.los_help.state_sharing': 'teamnav.papers.los_help.brains.state_sharing',
    'teamnav.control.coop.los_help.trouble_following': 'teamnav.papers.los_help.brains.trouble_following',
    'teamnav.control.coop.trail_share': 'teamnav.papers.trails.brains.trail_share',
    'teamnav.control.coop.trails': 'teamnav.papers.trails.brains.trails',
    'teamnav.control.delayed_integration': 'teamnav.papers.collab_mcl.brains.delayed_integration',
    'teamnav.control.localizing': 'teamnav.papers.collab_mcl.brains.localizing',
    'teamnav.control.mcl_wander_params': 'teamnav.papers.collab_mcl.brains.mcl_wander_params',
    'teamnav.control.negative_sights': 'teamnav.papers.collab_mcl.brains.negative_sights',
    'teamnav.control.tree_injection': 'teamnav.papers.collab_mcl.brains.tree_injection',
    'teamnav.experiments.beyond_case_scenarios': 'teamnav.papers.beyond.case_scenarios',
    'teamnav.experiments.beyond_localized_los': 'teamnav.papers.beyond.localized_los_scenarios',
    'teamnav.experiments.detection_training': 'teamnav.papers.collab_mcl.detection_training',
    'teamnav.experiments.los_tasks': 'teamnav.papers.los_help.tasks',
    'teamnav.experiments.metric_sets.faults': 'teamnav.papers.robustness.metrics',
    'teamnav.experiments.metric_sets.localization': 'teamnav.papers.collab_mcl.metrics',
    'teamnav.experiments.metric_sets.los_help': 'teamnav.papers.los_help.metrics',
    'teamnav.experiments.metric_sets.trails': 'teamnav.papers.trails.metrics',
    'teamnav.experiments.report.sections._beyond_detecting_trails': 'teamnav.papers.beyond.report._beyond_detecting_trails',
    'teamnav.experiments.report.sections._beyond_localized_los': 'teamnav.papers.beyond.report._beyond_localized_los',
    'teamnav.experiments.report.sections._beyond_mail_round': 'teamnav.papers.beyond.report._beyond_mail_round',
    'teamnav.experiments.report.sections._beyond_negative_detections': 'teamnav.papers.beyond.report._beyond_negative_detections',
    'teamnav.experiments.report.sections._beyond_trail_memory': 'teamnav.papers.beyond.report._beyond_trail_memory',
    'teamnav.experiments.report.sections._collab_beyond': 'teamnav.papers.collab_mcl.report._collab_beyond',
    'teamnav.experiments.report.sections._collab_common': 'teamnav.papers.collab_mcl.report._collab_common',
    'teamnav.experiments.report.sections._collab_delayed': 'teamnav.papers.collab_mcl.report._collab_delayed',
    'teamnav.experiments.report.sections._collab_detection': 'teamnav.papers.collab_mcl.report._collab_detection',
    'teamnav.experiments.report.sections._collab_tuning': 'teamnav.papers.collab_mcl.report._collab_tuning',
    'teamnav.experiments.report.sections._los_common': 'teamnav.papers.los_help.report._los_common',
    'teamnav.experiments.report.sections._los_reuse': 'teamnav.papers.los_help.report._los_reuse',
    'teamnav.experiments.report.sections._los_tables': 'teamnav.papers.los_help.report._los_tables',
    'teamnav.experiments.report.sections._los_verdicts': 'teamnav.papers.los_help.report._los_verdicts',
    'teamnav.experiments.report.sections._radio_beyond': 'teamnav.papers.beyond.report._radio_beyond',
    'teamnav.experiments.report.sections._trails': 'teamnav.papers.trails.report._trails',
    'teamnav.experiments.report.sections._trails_gap_fills': 'teamnav.papers.trails.report._trails_gap_fills',
    'teamnav.experiments.report.sections._trails_profile': 'teamnav.papers.trails.report._trails_profile',
    'teamnav.experiments.report.sections._try_blocks': 'teamnav.papers.trails.report._try_blocks',
    'teamnav.experiments.report.sections._try_long_runs': 'teamnav.papers.trails.report._try_long_runs',
    'teamnav.experiments.report.sections.beyond': 'teamnav.papers.beyond.report.section',
    'teamnav.experiments.report.sections.blazing_a_trail': 'teamnav.papers.trails.report.blazing_a_trail',
    'teamnav.experiments.report.sections.collab_mcl': 'teamnav.papers.collab_mcl.report.section',
    'teamnav.experiments.report.sections.los_help': 'teamnav.papers.los_help.report.section',
    'teamnav.experiments.report.sections.robustness': 'teamnav.papers.robustness.report.section',
    'teamnav.experiments.report.sections.try_to_see_it_my_way': 'teamnav.papers.trails.report.try_to_see_it_my_way',
    'teamnav.world.maps_collab_mcl': 'teamnav.papers.collab_mcl.maps',
    'teamnav.world.maps_los_help': 'teamnav.papers.los_help.maps',
    'teamnav.world.maps_trails': 'teamnav.papers.trails.maps',
}

#: old packages that only held moved modules: importable, empty, for ``import a.b.c`` to work
_OLD_PACKAGES = ("teamnav.control.coop", "teamnav.experiments.report.sections")


class _Alias(importlib.abc.Loader):
    """Gives the module at its new path; the import system's bookkeeping (``__spec__`` and the
    like, written between ``create_module`` and ``exec_module``) is undone so the module keeps
    its own name."""

    _KEEP = ("__name__", "__spec__", "__loader__", "__package__", "__path__", "__file__", "__cached__")

    def __init__(self, new: str | None) -> None:
        self.new = new
        self._saved: dict[str, object] = {}

    def create_module(self, spec):  # noqa: D102
        if self.new is None:
            return None  # an empty package
        warnings.warn(f"{spec.name} moved to {self.new}; the old path works for one release",
                      DeprecationWarning, stacklevel=4)
        module = importlib.import_module(self.new)
        self._saved = {k: module.__dict__[k] for k in self._KEEP if k in module.__dict__}
        return module

    def exec_module(self, module) -> None:  # noqa: D102
        if self.new is None:
            module.__path__ = []
            return
        for k in self._KEEP:
            if k in self._saved:
                setattr(module, k, self._saved[k])
            else:
                module.__dict__.pop(k, None)


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):  # noqa: D102
        if fullname in MOVED:
            return importlib.util.spec_from_loader(fullname, _Alias(MOVED[fullname]),
                                                   is_package=fullname in _IS_PACKAGE)
        if fullname in _OLD_PACKAGES:
            return importlib.util.spec_from_loader(fullname, _Alias(None), is_package=True)
        return None


_IS_PACKAGE = frozenset(old for old in MOVED if any(o.startswith(old + ".") for o in MOVED))


def install() -> None:
    """Put the finder of old paths on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.insert(0, _Finder())  # before the path finder: an old name never loads a file twice
