"""One module per paper; each defines ``SECTION`` (a :class:`~teamnav.experiments.report.model.SectionSpec`)."""
