"""The paper systems, one folder each, on a core that names no paper.

Each folder holds one system's robot code (``brains/``), maps, tasks, metric set, report
section(s), scenarios, sweeps and claims, and a README mapping the paper's rules to modules.
Each registers itself with the core through the ``teamnav.papers`` entry-point group
(:mod:`teamnav.plugins`), the same path an outside package uses to add a paper:

- :mod:`teamnav.papers.los_help`: Sgorbissa & Arkin, line-of-sight cooperative navigation;
- :mod:`teamnav.papers.collab_mcl`: Fox, Burgard, Kruppa & Thrun, collaborative multi-robot
  Monte Carlo localization;
- :mod:`teamnav.papers.trails`: Vaughan et al., Blazing a trail (2000) and Try to see it my
  way (2002);
- :mod:`teamnav.papers.beyond`: the four systems combined, and the papers' future work;
- :mod:`teamnav.papers.robustness`: faults injected into every system.
"""
