"""The toy paper's report section: its sweep, one table."""

from teamnav.experiments.report.model import SectionSpec, Table


def build(ctx):
    rows = ctx.sweep("toy-seeds", seeds=[0, 1], duration_s=2.0).rows()
    return [Table(title="Toy circles", columns=["seed", "path length [m]"],
                  rows=[[r["seed"], round(r["path_length_m_mean"], 3)] for r in rows])]


SECTION = SectionSpec(key="toy-paper", title="Toy paper: circles in a box", paper="", build=build, order=99)
