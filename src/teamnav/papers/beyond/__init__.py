"""Beyond the papers: the four systems combined (each beside its parts), and the papers'
future work. The brains here compose other papers' brains; each module says which rules it
composes. See ``README.md`` here.
"""

from teamnav.plugins import Paper, PaperSection

PAPER = Paper(
    key="beyond",
    title="Beyond the papers: the systems combined",
    package=__name__,
    brains={
        "localized-v1": "teamnav.papers.beyond.brains.localized:Localized",
        "los-trail-explorer-v1": "teamnav.papers.beyond.brains.trail_memory:LosTrailExplorer",
        "detecting-trails-v1": "teamnav.papers.beyond.brains.detecting:DetectingTrails",
    },
    sections=(
        PaperSection(
            key="beyond",
            module="teamnav.papers.beyond.report.section",
            title="Beyond the papers: the systems combined",
            order=95,
        ),
    ),
)
