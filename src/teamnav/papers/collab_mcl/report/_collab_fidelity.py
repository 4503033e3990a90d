"""The ``collab-mcl`` section's ledger and §5.1 precondition (``shared/FIDELITY.md`` §1-§2; Fox,
Burgard, Kruppa & Thrun 2000).

- :func:`ledger_blocks`: one :class:`~teamnav.experiments.report.model.Ledger` per column, a row per
  parameter of each scenario group that is not the brain's default, with its source (stated,
  implied, fill, ...) and where it comes from (:data:`PAPER_REFS`, :data:`TEAMNAV_REFS`, and the
  brain's ``PAPER_RULE_NOTES`` / ``GAP_FILLS_KEPT``);
- :func:`precondition_blocks`: the behaviours of single robots the paper reports and its claims rest
  on, each measured on tuning seeds and kept as package data (the report never runs tuning seeds):
  §5.1's (Robin alone still multi-modal when it passes the lab; rule 3,
  ``scripts/collab_mcl_fidelity.py precondition``, :data:`PRECONDITION`), §5.2.1's (single robots
  need minutes in the hallway; rule 10, ``scripts/collab_mcl_collapse.py hallway --conditions
  alone``) and §5.2.2's (alone, sonar and laser robots keep their symmetric places; rules 4 and 10,
  ``scripts/collab_mcl_fidelity.py modes``);
- :func:`gated_judge`: the claim file's verdict, or "precondition not met" for a claim that needs a
  precondition that did not hold (FIDELITY §1: never "fails" then).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from teamnav.experiments.report.model import Ledger, LedgerRow, Precondition

#: What ``scripts/collab_mcl_fidelity.py precondition`` measured (rule 3 of docs/report/collab-mcl.md,
#: "2026-11-29"): the tuning seeds, the heaviest mode per run, the threshold and the share needed.
PRECONDITION: dict = json.loads(
    (Path(__file__).resolve().parent / "data" / "collab-mcl-precondition.json").read_text(encoding="utf-8"))

#: the claims whose verdict needs the §5.1 precondition
PRECONDITION_CLAIMS: tuple[str, ...] = ("single-detection", "fp-breaks")

_DATA = Path(__file__).resolve().parent / "data"
#: rule 10 (docs/report/collab-mcl.md): §5.2.1's single robots in the hallway, §5.2.2's in the hexagon
HALLWAY_ALONE: dict = json.loads((_DATA / "collab-mcl-precondition-hallway.json").read_text(encoding="utf-8"))
HEXAGON_ALONE: dict = json.loads((_DATA / "collab-mcl-precondition-hexagon.json").read_text(encoding="utf-8"))

_RULES = 'docs/report/collab-mcl.md, "2026-11-29: rules written before the runs"'

#: paper column: field (flattened, "beam.sigma_hit_m") -> (source, ref), for fields that are not
#: PAPER_RULES (those take the brain's PAPER_RULE_NOTES, source "stated")
PAPER_REFS: dict[str, tuple[str, str]] = {
    "beam_stride": ("fill", f"rule 1 of {_RULES}: the highest mean posterior mass within 1 m / 30° of the true pose "
                            "among settings whose sample posterior matches a 0.2 m / 5° grid filter's (mean gap <= 0.1); "
                            "single scans, tuning seeds 1000-1009, corridor and hexagon (scripts/collab_mcl_beam_fill.py)"),
    "beam.sigma_hit_m": ("fill", "the laser's: rule 1 (as beam_stride); the sonar's 0.8 m with all 16 cones: rule 8 of "
                         f"{_RULES}, the same criterion over sigma_hit {{0.1 .. 2.0}} x cones {{16, 8, 4, 2}}, tuning seeds "
                         "1000-1009, symmetric hallway and hexagon (scripts/collab_mcl_beam_fill.py --sensor sonar); it "
                         "replaced the first version's 0.3 m, to which the judged run of 2026-11-29 traced both "
                         "paper-column failures"),
    "beam.z_hit": ("fill", "Fig. 1 gives the mixture's parts, not their weights; 0.7/0.1/0.1/0.1 kept from the first "
                           "version, not chosen by a rule"),
    "beam.z_short": ("fill", "as beam.z_hit"), "beam.z_max": ("fill", "as beam.z_hit"),
    "beam.z_rand": ("fill", "as beam.z_hit"),
    "adapt_ref_loglik_per_beam": ("fill", f"rule 2 of {_RULES}: the median per-beam log mean likelihood of a tracking "
                                          "filter (known start), tuning seeds 1000-1004 (scripts/collab_mcl_fidelity.py "
                                          "calibrate): Fox et al. 1999a's threshold on the summed likelihoods"),
    "max_particles": ("fill", "§3.1: 'many samples during global localization'; no count given; kept from the first "
                              "version"),
    "min_particles": ("fill", "§3.1 adapts the count; no floor given; kept from the first version"),
    "collaborate": ("stated", "§5: single-robot MCL against collaborative MCL"),
    "motion_mode": ("stated", "§5.1: 'Marian is operating in the lab facing towards the opening of the hallway'"),
    "init_pose": ("stated", "§5.1: Marian 'knows fairly well where it is' (position tracking from a known start)"),
    "wander": ("fill", "§5: the robots follow an operator or a random walk; our wanderer without turns into side "
                       "openings (tests/test_collab_hallway_wander.py), chosen on report seeds 0-7 (in-sample)"),
    "sensors.laser": ("stated", "§4.1: '180 distance measurements with approximately 5 cm accuracy, spaced at 1 degree'"),
    "sensors.sonar": ("fill", "§5.2: ultrasound sensors; 16 transducers, 15° cones, 5 cm noise are ours (first version)"),
    "map.lab_and_corridor": ("fill", f"Fig. 8 redrawn: alike offices every 5 m, the lab one of them; rule 3 of {_RULES} "
                                     "(the §5.1 precondition, checked on tuning seeds 1000-1009)"),
    "map.hexagon": ("stated", "§5.2.2: sonar robots cannot tell three locations apart, laser robots two"),
}

#: teamnav column: field -> ref (source "fill": teamnav's gap-fills beyond the paper)
TEAMNAV_REFS: dict[str, str] = {
    "likelihood_exponent": "1 in every group since 2026-11-29, as eq. 12 has it (rules 5 and 8 of docs/report/"
                           "collab-mcl.md): the tempering chosen on report seeds 0-7 (hallway 0.1, hexagon sonar 0.1 / "
                           "laser 0.01, §5.1 0.03) was for the beam models the fills replaced",
    "inject_fraction": "sensor resetting on a received tree (Lenser & Veloso 2000): what moves the §5.1 and §5.2 rows "
                       "of this column ('with sensor resetting')",
    "inject_heading_belief_share": "draws' headings not from the own belief; §5.1 and hallway: tuning seeds "
                                   "1000-1039 (the hexagon's uniform headings, chosen on report seeds, gave way to "
                                   "the brain's default by rule 9, tuning seeds 1000-1019)",
    "inject_heading_scan_share": "draws' headings picked by the scan; tuning seeds 1000-1039 (§5.1)",
    "inject_lost_prior": "§5.1: 0.6, re-chosen on tuning seeds 1000-1019 (rule 7 of docs/report/collab-mcl.md, "
                         "2026-11-29: lowest mean final error of Robin, 0.1-0.9); elsewhere the brain's 0.3, chosen "
                         "on report seed 7 (in-sample)",
    "resample_ess_fraction": "selective resampling (Doucet et al. 2000), not §3.1",
    "provenance": "rule 2 of §2.3 made transitive (beyond the paper)",
    "receive_gate": "rule 2 of §2.3 on the receiving side too (beyond the paper)",
    "adapt": "KLD-sampling (Fox 2003), not the 1999a rule the paper cites",
    "anonymous": "§7.2 extension: sights without identity associated by belief",
}


#: settings that the paper's rules make inert (inject_fraction 0, no negative sights, no delay)
_INERT = ("inject_", "neg_", "delay_", "send_max_cluster", "fp_", "assoc_")


def _flat(params: dict, prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in (params or {}).items():
        if isinstance(v, dict) and k in ("beam", "likelihood_field"):
            out.update(_flat(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def ledger_rows() -> list[LedgerRow]:
    """Both columns' rows for the three scenarios (see the module docstring)."""
    from teamnav.experiments.spec import load_scenario
    from teamnav.papers.collab_mcl.brains.mcl_wander_params import MCLWanderParams as P
    from teamnav.papers.trails.report._trails import paper_rules_spec

    rows: list[LedgerRow] = []
    for scen in ("collab-mcl-detection", "collab-mcl-hallway", "collab-mcl-hexagon"):
        s = load_scenario(scen)
        mname = s.map.builtin if hasattr(s.map, "builtin") else None
        paper_set = paper_rules_spec(scen).set
        for col in ("paper", "teamnav"):
            if mname and f"map.{mname}" in PAPER_REFS:
                src, ref = PAPER_REFS[f"map.{mname}"]
                rows.append(LedgerRow(col, f"{scen}: map", mname, src, ref))
        for i, g in enumerate(s.robots):
            head = f"{scen} / {g.name}"
            for sensor in g.sensors:
                kind = sensor.kind
                desc = {k: v for k, v in sensor.model_dump().items() if k in ("n_beams", "fov_deg", "noise_std_m",
                                                                              "n_transducers", "cone_deg")}
                src, ref = PAPER_REFS[f"sensors.{kind}"]
                for col in ("paper", "teamnav"):
                    rows.append(LedgerRow(col, f"{head}: {kind}", json.dumps(desc, sort_keys=True), src, ref))
            ours = _flat(g.params or {})
            paper = {k: v for k, v in _flat(paper_set.get(f"robots.{i}.params", {})).items() if k != "paper_rules"}
            paper.update({k: v for k, v in P.PAPER_RULES.items() if k not in paper})
            default = _flat(P().model_dump())
            for k, v in sorted(paper.items()):
                if k not in P.PAPER_RULES and k.startswith(_INERT):
                    continue  # inert under the paper's rules (GAP_FILLS_KEPT says so)
                if k in P.PAPER_RULES:
                    if default.get(k) == v and k not in ours:
                        continue
                    rows.append(LedgerRow("paper", f"{head}: {k}", v, "stated", P.PAPER_RULE_NOTES[k]))
                elif k in PAPER_REFS:
                    rows.append(LedgerRow("paper", f"{head}: {k}", v, *PAPER_REFS[k]))
                else:
                    why = P.GAP_FILLS_KEPT.get(k.split(".")[0], "a kept gap-fill of the first version")
                    rows.append(LedgerRow("paper", f"{head}: {k}", v, "fill", f"{why} (not chosen by a rule)"))
            for k, v in sorted(ours.items()):
                if k in TEAMNAV_REFS:
                    rows.append(LedgerRow("teamnav", f"{head}: {k}", v, "fill", TEAMNAV_REFS[k]))
                elif k in PAPER_REFS:
                    rows.append(LedgerRow("teamnav", f"{head}: {k}", v, *PAPER_REFS[k]))
                else:
                    why = P.GAP_FILLS_KEPT.get(k.split(".")[0], "teamnav's gap-fill (brains/mcl_wander_params.py)")
                    rows.append(LedgerRow("teamnav", f"{head}: {k}", v, "fill", why))
            for k, v in sorted(P.PAPER_RULES.items()):  # teamnav's own values of the paper's rules
                if k not in ours and default.get(k) != v and k in TEAMNAV_REFS:
                    rows.append(LedgerRow("teamnav", f"{head}: {k}", default.get(k), "fill", TEAMNAV_REFS[k]))
    return rows


def ledger_blocks() -> list[Ledger]:
    """The paper column's ledger, then teamnav's."""
    rows = ledger_rows()
    return [Ledger([r for r in rows if r.column == "paper"], "Ledger, paper as written (judged): where each "
                   "parameter comes from", note="One row per scenario group and parameter that is not the brain's "
                   "default. 'fill': a silence of the paper, with the rule and tuning seeds it was chosen by, or "
                   "'not chosen by a rule' where it was kept from the first version."),
            Ledger([r for r in rows if r.column == "teamnav"], "Ledger, teamnav: its gap-fills",
                   note="Values chosen on report seeds say so (in-sample).")]


def precondition_holds() -> bool | None:
    return PRECONDITION.get("holds")


def precondition_block() -> Precondition:
    p = PRECONDITION
    hm = p.get("heaviest_mode", [])
    result = (f"heaviest mode of Robin's belief at the lab door per run: "
              f"{', '.join('n/a' if h is None else f'{h:.2f}' for h in hm)}; <= {p['threshold']} in "
              f"{p['runs_ok']} of {len(hm)} runs (needed: {p['runs_needed']}; n/a: Robin never reached the door "
              f"in 110 s); map {p['map']}; " + (f"{p['also']}; " if p.get("also") else "")
              + f"measured {p['date']} ({p['cpu_s']:.0f} CPU s, scripts/collab_mcl_fidelity.py precondition). "
              "Mechanism: every period of the corridor fits Robin's scans, and resampling at every update "
              "(§3.1) lets one period win by drift before Robin reaches the lab")
    return Precondition("§5.1 / Fig. 10(a): Robin alone (paper as written, no detections) is still multi-modal "
                        "when it passes the lab ('still highly uncertain about its exact location within the "
                        "corridor and even does not know its global heading direction'): no mode (the samples "
                        f"within 1 m of one) holds more than {p['threshold']} of its belief",
                        p["seeds"], result, p.get("holds"), PRECONDITION_CLAIMS)


def hallway_block() -> Precondition:
    """§5.2.1: single robots need minutes to localize in the hallway (rule 10)."""
    p = HALLWAY_ALONE
    runs = ", ".join(f"{t:.0f}" for t in p["ttl_s"])
    result = (f"time to localize alone (per run, mean over the 8 robots, censored at {p['duration_s']:.0f} s): "
              f"{runs} s; mean {p['mean_ttl_s']:.1f} s against the {p['threshold_s']:.0f} s needed (half of the "
              f"paper's 379 s); robots never below 1.5 m: {p['censored']} of {8 * len(p['ttl_s'])}; measured "
              f"{p['date']} ({p['cpu_s']:.0f} CPU s, {p['script']}). {p['why']}")
    return Precondition("§5.2.1: a single robot in the symmetric hallway needs minutes to localize ('a robot "
                        "needs 379 ± 37 seconds to uniquely determine its position'): robots alone, paper as "
                        f"written, take on average at least {p['threshold_s']:.0f} s",
                        p["seeds"], result, p["holds"], ("hallway-faster",))


def hexagon_block() -> Precondition:
    """§5.2.2: alone, a sonar robot keeps three places and a laser robot two (rules 4 and 10)."""
    p = HEXAGON_ALONE
    result = (f"modes of the belief at {p['t_s']:.0f} s alone, per run: sonar {p['sonar_modes']}, laser "
              f"{p['laser_modes']} (needed: >= 2 each in {p['runs_needed']} of {len(p['sonar_modes'])} runs); "
              f"measured {p['date']} ({p['script']}). {p['why']}")
    return Precondition("§5.2.2, Fig. 13 (c), (d): alone, sonar robots 'cannot distinguish between three possible "
                        "robot locations' and laser robots 'remain uncertain about two possible locations': "
                        "each keeps at least 2 modes", p["seeds"], result, p["holds"], ("hexagon-together",))


def precondition_blocks() -> list[Precondition]:
    """Every precondition of the section, in the order of the paper."""
    return [precondition_block(), hallway_block(), hexagon_block()]


def gated_judge(claim, values: dict) -> tuple[bool | None, str]:
    """:func:`teamnav.experiments.claims.judge`, or ``(None, "precondition not met ...")`` for a claim
    that needs a precondition which did not hold on its tuning seeds (:func:`precondition_blocks`)."""
    from teamnav.experiments.claims import judge

    for p in precondition_blocks():
        if claim.id in p.claims and p.holds is not True:
            h, text = judge(claim, values)
            return None, (f"precondition not met ({p.what.split(':')[0]}, tuning seeds {p.seeds}: "
                          f"{'not checked' if p.holds is None else 'does not hold'}); the rule would read: {text}")
    return judge(claim, values)
