"""teamnav: simulator, library and CLI for robot teams that help each other navigate.

The two entry points for scripts::

    from teamnav import load_scenario, run
    result = run(load_scenario("demo", duration_s=10), out_dir="runs/demo-10s")
    print(result.metrics["path_length_m_mean"])
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

from teamnav import _moved_paths  # old import paths of the papers' modules, one release

_moved_paths.install()

# numba's caches of the kernels whose callees in another module changed are renewed
from teamnav import _kernel_caches

_kernel_caches.renew()

__all__ = ["__version__", "load_scenario", "run", "sweep"]

if TYPE_CHECKING:  # pragma: no cover
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep import sweep


def __getattr__(name: str) -> Any:
    # Lazy, so `import teamnav` (and the brains under teamnav.control) stay light and never
    # pull in the experiments layer.
    if name == "load_scenario":
        from teamnav.experiments.spec import load_scenario

        return load_scenario
    if name == "run":
        from teamnav.experiments.runner import run

        return run
    if name == "sweep":
        from teamnav.experiments.sweep import sweep

        return sweep
    raise AttributeError(f"module 'teamnav' has no attribute {name!r}")
