"""A toy paper: robots that circle in a box. Registered with teamnav by the entry point
``toy = toy_paper:PAPER`` of the group ``teamnav.papers``."""

from teamnav.plugins import Paper, PaperSection

PAPER = Paper(
    key="toy",
    title="A toy paper: robots circling in a box",
    package=__name__,
    brains={"toy-circler-v1": "toy_paper.brain:Circler"},
    maps={"toy_box": "toy_paper.maps:toy_box", "toy_box_wide": ("toy_paper.maps:toy_box", {"width_m": 8.0})},
    metric_sets={"toy": "toy_paper.metrics"},
    sections=(PaperSection(key="toy-paper", module="toy_paper.section", title="Toy paper", order=99),),
)
