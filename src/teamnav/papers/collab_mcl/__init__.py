"""Fox, Burgard, Kruppa & Thrun: collaborative multi-robot Monte Carlo localization (a
particle filter per robot, the detection model, density trees carrying one robot's belief into
another's). The filter, models and trees are the core's :mod:`teamnav.localization`; this
folder holds the paper's brain, maps, detection training, metric set and report. See
``README.md`` here for the paper's rules by module.
"""

from teamnav.plugins import Paper, PaperSection

PAPER = Paper(
    key="collab_mcl",
    title="Fox, Burgard, Kruppa & Thrun: collaborative multi-robot localization",
    package=__name__,
    brains={"mcl-wander-v1": "teamnav.papers.collab_mcl.brains.localizing:MCLWander"},
    maps={
        "symmetric_hallway": "teamnav.papers.collab_mcl.maps:symmetric_hallway",
        "hexagon": "teamnav.papers.collab_mcl.maps:hexagon",
        "lab_and_corridor": "teamnav.papers.collab_mcl.maps:lab_and_corridor",
    },
    metric_sets={"localization": "teamnav.papers.collab_mcl.metrics"},
    sections=(
        PaperSection(
            key="collab-mcl",
            module="teamnav.papers.collab_mcl.report.section",
            title="Fox, Burgard, Kruppa & Thrun: collaborative multi-robot localization",
            paper="fox-burgard-kruppa-thrun-collaborative-multi-robot-localization.txt",
            order=20,
        ),
    ),
)
