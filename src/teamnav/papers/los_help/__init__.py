"""Sgorbissa & Arkin: line-of-sight cooperative navigation (goal sharing, ghost robots, state
sharing) on top of three local navigators. See ``README.md`` here for the paper's rules by
module.
"""

from teamnav.plugins import Paper, PaperSection

PAPER = Paper(
    key="los_help",
    title="Sgorbissa & Arkin: line-of-sight help",
    package=__name__,
    brains={
        "los-explorer-v1": "teamnav.papers.los_help.brains.explorer:LosExplorer",
        "los-helper-v1": "teamnav.papers.los_help.brains.helper:LosHelper",
    },
    maps={
        "office_simple": "teamnav.papers.los_help.maps:office_simple",
        "office_complex": "teamnav.papers.los_help.maps:office_complex",
        "office_complex_closed": ("teamnav.papers.los_help.maps:office_complex", {"alleys": False}),
        "office_simple_grid": "teamnav.papers.los_help.maps:office_simple_grid",
    },
    metric_sets={"los_help": "teamnav.papers.los_help.metrics"},
    sections=(
        PaperSection(
            key="los-help",
            module="teamnav.papers.los_help.report.section",
            title="Sgorbissa & Arkin: line-of-sight help",
            paper="sgorbissa-arkin-local-navigation-strategies-for-a-team-of-robots.txt",
            order=10,
        ),
    ),
)
