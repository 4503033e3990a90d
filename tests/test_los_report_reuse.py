"""The los-help section runs no simulation twice.

The noise figures' err_max = 0 points and the ablation's columns that equal the tables' settings
are read from the tables' R1..R4 rows when (and only when) their trials are the same resolved
scenario with the same seed (``_los_reuse.reused_rows``)."""

from __future__ import annotations

import pytest

from teamnav.papers.los_help.report import _los_reuse as RU
from teamnav.papers.los_help.report._los_common import ERR_KEY, TARGETS_KEY
from teamnav.experiments.sweep import expand, resolve_spec

TASK = [[[4.1, -7.9], [4.1, -2.0]], [[-4.1, -19.9], [4.1, -13.9]]]


def _zero_spec():
    return resolve_spec("los-noise-simple", grid={ERR_KEY: [0.0], TARGETS_KEY: TASK})


def _rows_of(spec, **extra):
    return [{"trial_id": t.trial_id, "status": "ok", "seed": t.seed, "config_hash": t.config_hash,
             "params": {**t.params, **extra}, "metrics": {"los_steps_per_target": 100.0 + i}}
            for i, t in enumerate(expand(spec))]


def test_reused_rows_one_per_trial_in_order_with_params_written():
    spec = _zero_spec()
    rows = _rows_of(spec)
    rows_shuffled = rows[::-1] + [{**rows[0], "config_hash": "0" * 16}]  # order and a stranger do not matter
    got = RU.reused_rows(spec, rows_shuffled, {ERR_KEY: 0.0, "tag": "x"})
    assert got is not None and len(got) == len(rows) == 6  # 3 algorithms x 2 tasks
    assert [r["metrics"] for r in got] == [r["metrics"] for r in rows]
    assert all(r["params"]["tag"] == "x" and r["params"][ERR_KEY] == 0.0 for r in got)
    assert "tag" not in rows[0]["params"]  # the source rows are not modified


@pytest.mark.parametrize("spoil", ["drop", "seed", "hash", "no_hash"])
def test_reused_rows_none_unless_every_trial_is_the_same_simulation(spoil):
    spec = _zero_spec()
    rows = _rows_of(spec)
    if spoil == "drop":
        rows = rows[1:]
    elif spoil == "seed":
        rows[2] = {**rows[2], "seed": rows[2]["seed"] + 1}
    elif spoil == "hash":
        rows[3] = {**rows[3], "config_hash": "f" * 16}
    else:
        rows[0] = {k: v for k, v in rows[0].items() if k != "config_hash"}
    assert RU.reused_rows(spec, rows, {ERR_KEY: 0.0}) is None
    assert RU.reused_rows(spec, [], {ERR_KEY: 0.0}) is None


def test_err_max_zero_of_the_noise_sweep_is_a_different_simulation_at_err_max_0_1():
    """The check has teeth: the noise sweep's err_max = 0.1 trials are not its err_max = 0 ones."""
    a = RU.trial_keys(_zero_spec())
    b = RU.trial_keys(resolve_spec("los-noise-simple", grid={ERR_KEY: [0.1], TARGETS_KEY: TASK}))
    assert not set(a) & set(b)


class _AnyMetric(dict):
    def get(self, key, default=None):
        return 1.0

    def __len__(self):
        return 1


def test_full_build_asks_for_no_simulation_twice_and_reads_the_duplicates_from_the_tables(memo_scenario_yaml, tmp_path):
    """Full mode: 780 trials asked before 14d5e61, 75 of them the same simulation as another
    (noise err_max = 0: 2 maps x 3 algorithms x 5 tasks x 2 columns; ablation: 3 x 5); then 705,
    every (config_hash, seed) once, and the noise figures still get err_max 0 for every algorithm,
    task and column. On the judged tasks 11-20 (ten, not five) the counts double: 1410; the Avoid-Past
    half-life readings add their own trials (none the same simulation as another: the fill's rows are
    the table's)."""
    from teamnav.experiments.report import available_sections
    from teamnav.experiments.report.context import SweepContext
    from teamnav.papers.los_help.report import section as S

    asked: dict[tuple[str, int], str] = {}
    twice: list[tuple[str, str]] = []
    noise_zero: dict[str, int] = {}

    class Listing(SweepContext):
        def sweep(self, name_or_spec, **kw):
            spec = resolve_spec(name_or_spec, **{k: kw.pop(k) for k in ("grid", "seeds", "set", "duration_s", "name")
                                                 if k in kw})
            rows = []
            for t in expand(spec):
                key = (t.config_hash, t.seed)
                if key in asked:
                    twice.append((asked[key], spec.sweep_name))
                asked[key] = spec.sweep_name
                rows.append({"trial_id": t.trial_id, "status": "ok", "seed": t.seed, "config_hash": t.config_hash,
                             "params": dict(t.params), "metrics": _AnyMetric()})

            class R:
                def rows(self, **_):
                    return rows
            return R()

    orig = S.run_noise

    def run_noise(ctx, map_key, all_helpers, col="teamnav"):
        out = orig(ctx, map_key, all_helpers, col)
        noise_zero[f"{map_key}/{col}"] = sum(1 for r in out if float(r["params"].get(ERR_KEY, -1)) == 0.0)
        return out

    S.run_noise = run_noise
    try:
        available_sections()["los-help"].build(Listing(tmp_path, quick=False, section="los-help"))
    finally:
        S.run_noise = orig
    assert not twice
    n_tasks = len(S.L.JUDGED_TASKS)
    from teamnav.papers.los_help.report import _los_half_life as HL

    assert len(asked) == 705 * n_tasks // 5 + HL.trials()
    assert HL.trials() == len(HL.to_run()) * 4 * n_tasks and HL.fill() not in HL.to_run()
    assert noise_zero == {f"{m}/{c}": 3 * n_tasks for m in ("simple", "complex") for c in ("teamnav", "paper_rules")}
