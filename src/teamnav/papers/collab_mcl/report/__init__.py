"""The ``collab-mcl`` report section (:mod:`.section`) and its parts: §5.1 detection, §7.2 variants, delayed integration, tuning-seed tables, the two columns."""
