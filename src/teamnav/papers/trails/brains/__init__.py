"""Vaughan et al.'s robot code: crumbs and their average-heading query (:mod:`.crumbs`, 2000
§4), the 2000 forager ``blazing-trail-v1`` (:mod:`.blazing_trail`), the 2002 Places, Crumbs and
Trails (:mod:`.trails`) and their forager ``trail-share-v1`` (:mod:`.trail_share`), and the
foraging loop both share (:mod:`.forager`). Navigate, Panic and wall following are the core's
:mod:`teamnav.control.nav`. Robot code: nothing here reads the simulator's truth.
"""
