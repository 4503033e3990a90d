"""The ``robustness`` report section (:mod:`.section`): each system with and without its faults."""
