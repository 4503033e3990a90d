"""Line-of-sight help: goal sharing, ghost robots and state sharing (Sgorbissa & Arkin).

Modules: :mod:`.messages` (message bodies), :mod:`.goal_sharing` (§3–§4 rules: Id, frames
from mutual bearings, reflected/delayed visibility, §4.3 bookkeeping), :mod:`.state_sharing`
(§5 Tr/Pr/Cr/Nt), :mod:`.brain` (the ``los-explorer-v1`` and ``los-helper-v1`` brains).
"""

from teamnav.control.coop.los_help.brain import LosExplorer, LosExplorerParams, LosHelper, LosHelperParams

__all__ = ["LosExplorer", "LosExplorerParams", "LosHelper", "LosHelperParams"]
