"""The ``los-help`` report section (:mod:`.section`): Tables 1-2, Figs. 16-17 and the sharing ablation, in both columns."""
