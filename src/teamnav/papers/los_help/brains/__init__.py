"""Line-of-sight help: goal sharing, ghost robots and state sharing (Sgorbissa & Arkin).

Modules: :mod:`.messages` (message bodies), :mod:`.goal_sharing` (§3–§4 rules: Id, frames
from mutual bearings, reflected/delayed visibility, §4.3 bookkeeping), :mod:`.state_sharing`
(§5 Tr/Pr/Cr/Nt), :mod:`.params` (the parameters both brains share, the paper's rules among
them), :mod:`.brain` (the step both brains share), :mod:`.driving` (heading for a point: straight
or with algorithm A), :mod:`.explorer` (``los-explorer-v1``, R1; its parameters in
:mod:`.explorer_params`) and :mod:`.helper` (``los-helper-v1``, R2..R4).
"""

from teamnav.papers.los_help.brains.explorer import LosExplorer, LosExplorerParams
from teamnav.papers.los_help.brains.helper import LosHelper, LosHelperParams

__all__ = ["LosExplorer", "LosExplorerParams", "LosHelper", "LosHelperParams"]
