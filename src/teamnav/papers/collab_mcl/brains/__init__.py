"""Fox, Burgard, Kruppa & Thrun's robot code: the localizing brain ``mcl-wander-v1``
(:mod:`.localizing`, its parameters and paper rules in :mod:`.mcl_wander_params`) and §7.2's
rules: :mod:`.delayed_integration`, :mod:`.anonymous_association`, :mod:`.negative_sights`,
:mod:`.tree_injection`. The filter, models and density trees are the core's
:mod:`teamnav.localization`. Robot code: nothing here reads the simulator's truth.
"""
