"""Vaughan, Stoy, Sukhatme & Mataric: trails of crumbs, in one odometric frame ("Blazing a
trail", 2000) and across unrelated frames through task-level Places ("Try to see it my way",
2002). See ``README.md`` here for the papers' rules by module.
"""

from teamnav.plugins import Paper, PaperSection

PAPER = Paper(
    key="trails",
    title="Vaughan et al.: Blazing a trail (2000) and Try to see it my way (2002)",
    package=__name__,
    brains={
        "blazing-trail-v1": "teamnav.papers.trails.brains.blazing_trail:BlazingTrail",
        "trail-share-v1": "teamnav.papers.trails.brains.trail_share:TrailShare",
    },
    maps={
        "trail_office": "teamnav.papers.trails.maps:trail_office",
        "trail_office_corridors": ("teamnav.papers.trails.maps:trail_office", {"doors": False}),
        "trail_office_z": ("teamnav.papers.trails.maps:trail_office", {"shape": "z"}),
        "trail_office_z_corridors": ("teamnav.papers.trails.maps:trail_office", {"doors": False, "shape": "z"}),
    },
    metric_sets={"trails": "teamnav.papers.trails.metrics"},
    sections=(
        PaperSection(
            key="blazing-a-trail",
            module="teamnav.papers.trails.report.blazing_a_trail",
            title="Vaughan et al.: Blazing a trail",
            paper="vaughan-stoy-sukhatme-mataric-blazing-a-trail.txt",
            order=30,
        ),
        PaperSection(
            key="try-to-see-it-my-way",
            module="teamnav.papers.trails.report.try_to_see_it_my_way",
            title="Vaughan et al.: Try to see it my way",
            paper="vaughan-stoy-sukhatme-mataric-try-to-see-it-my-way.txt",
            order=40,
        ),
    ),
)
