"""Robustness: faults injected into every system (robots that die, radio blackouts,
kidnappings, phantom detections), each beside the fault-free run on the same seeds. The faults
themselves are the simulator's (:mod:`teamnav.sim.faults`); this folder holds the metric set
and the report section.
"""

from teamnav.plugins import Paper, PaperSection

PAPER = Paper(
    key="robustness",
    title="Robustness: faults injected and survived",
    package=__name__,
    metric_sets={"faults": "teamnav.papers.robustness.metrics"},
    sections=(
        PaperSection(
            key="robustness",
            module="teamnav.papers.robustness.report.section",
            title="Robustness: faults injected and survived",
            order=90,
        ),
    ),
)
