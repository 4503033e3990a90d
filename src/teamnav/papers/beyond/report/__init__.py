"""The ``beyond`` report section (:mod:`.section`) and its blocks, one module each."""
