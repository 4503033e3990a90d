"""Profiled trail runs: a run sampled for memory (process RSS, crumbs held) and CPU per simulated
hour as it goes (the stated targets "memory stays flat over a 10-hour simulated run" and "a simulated hour
of 4 robots runs in well under a minute on one core"); :func:`profile_trial` is the sweep
``trial_fn`` of the try-to-see-it-my-way section's profiled runs.

Split from :mod:`._trails` (no behaviour change; ``_trails`` re-exports these names).
"""

from __future__ import annotations

import json


def _rss_mb() -> float:
    """This process's resident set size now [MiB] (Linux /proc; peak RSS elsewhere)."""
    try:
        with open("/proc/self/statm", encoding="ascii") as f:
            pages = int(f.read().split()[1])
        import os

        return pages * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (OSError, ValueError, IndexError):
        import resource
        import sys

        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / (2**20 if sys.platform == "darwin" else 2**10)


def profile_run(sc, every_steps: int) -> tuple[list[dict], dict]:
    """Run the loaded scenario ``sc`` in chunks of ``every_steps`` and sample memory and CPU after each.

    The stated targets "memory stays flat over a 10-hour simulated run (crumb expiry works)" and "a simulated
    hour of 4 robots runs in well under a minute on one core". Give ``sc`` a large ``record_every``
    (the recorder keeps every recorded step, so a small one makes the recorder's own memory grow with
    the run; events are recorded whatever ``record_every``).

    Returns
    -------
    samples : list of dict
        Per sample: ``t_h``, ``rss_mb`` (process RSS now), ``crumbs_max`` (largest crumb list over
        the robots, from the brains' logged ``n_crumbs``), ``crumbs_total``, ``cpu_s`` (process CPU
        time of this interval) and ``cpu_s_per_h`` (the same per simulated hour).
    metrics : dict
        The run's trail metrics (:func:`teamnav.papers.trails.metrics.trail_metrics` and
        ``trail_series``), from its full event log.
    """
    import gc
    import shutil
    import tempfile
    import time
    from pathlib import Path

    from teamnav.papers.trails import metrics as M
    from teamnav.experiments.runner import run_data
    from teamnav.experiments.spec import build_grid
    from teamnav.sim.engine import Simulation

    if isinstance(every_steps, bool) or not isinstance(every_steps, int) or every_steps < 1:
        raise ValueError(f"every_steps must be an int >= 1, got {every_steps!r}")
    grid = build_grid(sc)
    sim = Simulation(grid, sc)
    n_total = sc.n_steps
    samples: list[dict] = []
    done = 0
    while done < n_total:
        k = min(every_steps, n_total - done)
        c0 = time.process_time()
        sim.run(k)
        cpu = time.process_time() - c0
        done += k
        gc.collect()
        crumbs = [float(b.log().get("n_crumbs", 0)) for group in sim.brains for b in group if hasattr(b, "log")]
        samples.append({"t_h": done * sc.dt_s / 3600.0, "rss_mb": _rss_mb(),
                        "crumbs_max": max(crumbs, default=0.0), "crumbs_total": float(sum(crumbs)),
                        "cpu_s": cpu, "cpu_s_per_h": cpu / (k * sc.dt_s / 3600.0)})
    sim.record_last_step()
    staging = Path(tempfile.mkdtemp(prefix="teamnav-profile-"))
    try:
        sim.recorder.save(staging)
        data = run_data(staging, sc, grid, int(sim.step_index), 0.0)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return samples, {**M.trail_metrics(data), **M.trail_series(data)}


def long_run_profile(scenario: str = "try-to-see-it-my-way", *, hours: float = 10.0, sample_every_s: float = 1800.0,
                     seed: int = 0, overrides: dict | None = None) -> tuple[list[dict], dict]:
    """:func:`profile_run` of a named scenario for ``hours``, sampled every ``sample_every_s``.

    Raises
    ------
    ValueError
        ``hours`` or ``sample_every_s`` not positive.
    """
    from teamnav.experiments.spec import load_scenario

    if not (hours > 0 and sample_every_s > 0):
        raise ValueError(f"hours and sample_every_s must be > 0, got {hours!r}, {sample_every_s!r}")
    every = max(1, int(round(sample_every_s / load_scenario(scenario).dt_s)))
    sc = load_scenario(scenario, overrides={**(overrides or {}), "record_every": every}, seed=seed,
                       duration_s=hours * 3600.0)
    return profile_run(sc, every)


def profile_trial(scenario, out_dir=None) -> dict:
    """A sweep ``trial_fn``: :func:`profile_run` sampled every ``record_every`` steps, as flat metrics.

    Keys: the trail metrics, ``cpu_s_per_h`` (whole run), ``cpu_s_per_h_max`` (worst interval),
    ``rss_mb_first`` / ``rss_mb_last`` (after the first / last interval), ``rss_growth_mb``,
    ``crumbs_held_max_first_half`` / ``crumbs_held_max_second_half`` (sampled) and
    ``profile_series`` (the samples, JSON).
    """
    samples, metrics = profile_run(scenario, int(scenario.record_every))
    hours = sum(s["cpu_s"] / s["cpu_s_per_h"] for s in samples if s["cpu_s_per_h"] > 0) or float("nan")
    half = 0.5 * samples[-1]["t_h"]
    first = [s["crumbs_max"] for s in samples if s["t_h"] <= half]
    second = [s["crumbs_max"] for s in samples if s["t_h"] > half]
    out = {k: v for k, v in metrics.items() if isinstance(v, (int, float, str)) and not isinstance(v, bool)}
    out.update({
        "cpu_s_per_h": float(sum(s["cpu_s"] for s in samples) / hours),
        "cpu_s_per_h_max": float(max(s["cpu_s_per_h"] for s in samples)),
        "rss_mb_first": float(samples[0]["rss_mb"]), "rss_mb_last": float(samples[-1]["rss_mb"]),
        "rss_growth_mb": float(samples[-1]["rss_mb"] - samples[0]["rss_mb"]),
        "crumbs_held_max_first_half": float(max(first, default=0.0)),
        "crumbs_held_max_second_half": float(max(second, default=0.0)),
        "profile_series": json.dumps([{k: round(v, 3) for k, v in s.items()} for s in samples], separators=(",", ":")),
    })
    return out
