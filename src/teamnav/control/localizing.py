"""A robot that wanders while it localizes itself, alone or with its team (Fox et al.).

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization", Autonomous Robots 8(3), 2000. The brain ``mcl-wander-v1``:

- *moves* with the wanderer of :mod:`teamnav.control.nav.wander` (wall following, random
  turns at openings, obstacle avoidance from the range scan; the paper's robots are driven
  by an operator or a random walk, §5);
- *localizes* with its own :class:`~teamnav.localization.MCL` (§3.1): global initialisation
  uniform over the free space of ``info.known_map`` (§2.2, Fig. 4a), odometry motion model,
  beam model of its sensor (sonar cones or laser, Fig. 1) or the likelihood field, a few
  uniform random samples per step, KLD-adaptive sample count (§3.1 "MCL determines the
  sample set size on-the-fly");
- with ``collaborate`` it *synchronises* beliefs on detections (§2.3, §3.2, eqs. 10, 13, 14)
  through :class:`~teamnav.localization.BeliefSync`: a detection becomes a density tree of
  the seen robot's position, sent over the radio (its bytes counted by ``Message.size_bytes``);
  the seen robot multiplies it into its weights and answers with its own position tree so that
  the observer is constrained too; negative sights are ignored and a robot is not used again
  until the user has travelled ``min_travel_m`` = 2.5 m (§2.3 rules 1 and 2).

Detections are looked at once per ``detection_period_s`` (1 s: "images are analyzed at a
rate of 1 Hz", §4.1); the simulator's detector reports every step, so its false-positive rate
per step is the rate per camera frame as the brain sees it.

Where the brain fills gaps of the paper (each a parameter, the paper's behaviour reachable):
the filter runs once odometry accumulated ``min_update_m`` / ``min_update_deg`` (the steps in
between are composed, as AMCL does); it resamples only when the effective sample size fell
below ``resample_ess_fraction`` of the set (1 = every update, as §3.1); the likelihood is
tempered by ``likelihood_exponent`` (neighbouring beams are not independent); and with
``inject_fraction`` > 0 a received tree first replaces that share of the samples by draws from
it (sensor resetting) before eq. 14 reweights them, because our sample sets (thousands per
robot) lose the true mode of a symmetric belief long before a detection arrives, and eq. 14
alone cannot move weight onto samples that do not exist.

Against double counting and wrong senders (measured on the failing runs of the first version,
each fix a parameter with the first behaviour one flag away):

- the draws get the posterior probability that the receiver is lost (``inject_weighting``,
  ``inject_lost_prior``), not the tree's density a second time: drawing from the tree and then
  multiplying the tree in counted the detection twice and handed a receiver to any sender
  whose tree contradicted it, right or wrong (in the hexagon, pairs of robots swapped their
  right and wrong beliefs at every exchange);
- the §2.3 reply is built from the belief before the draws (``inject_before_reply``): it
  carried the sender's own claim back to it, which then confirmed its own belief;
- the draws take headings from the own belief (``inject_heading_belief_share``): a detection
  sees no heading, and with uniform headings the mirror pose of a featureless corridor (other
  side of the axis, heading reversed) won a §5.1 run;
- ``provenance``: rule 2 made transitive (:class:`~teamnav.localization.SyncParams`): a robot
  drops a tree holding its own information from less than 2.5 m of travel ago that came back
  through a third robot.

Beyond the paper (each behind a flag, measured in the ``collab-mcl`` report section):

``false_positive_filter`` (§7.2: "a rate of 3.5 % ... turns out to cause major problems")
    Three gates, two at the observer and one at the detected robot:

    1. *map consistency*: the detected position, sampled through the detection model from
       the observer's belief, must fall in free space of the known map with at least
       ``fp_min_free_mass`` of the belief's weight (a phantom at a uniform range and bearing
       lands in a wall or outside the building most of the time in hallways);
    2. *confirmation*: a detection is used only when the same robot was also seen on the
       previous camera frame (at most ``fp_confirm_window_s`` before) at a consistent place:
       the two detected points, each expressed in the observer's odometry frame, lie within
       ``fp_confirm_gate_m`` of each other. Phantoms are independent per frame with random
       identities and positions, so two consistent phantoms are rare (≈ p_fp² × gate area /
       field area), while a true teammate is seen on consecutive frames;
    3. *belief agreement* (at the detected robot, off by default: ``fp_min_real_prob`` = 0):
       the posterior probability that the detection is real, ``(1 - p_fp) E / ((1 - p_fp) E +
       p_fp / A)`` with ``E = sum_i w_i tree(x_i)`` the tree's density under the own belief and
       ``A`` the free area, must be at least ``fp_min_real_prob``. Measured on the §5.1 setting
       it also drops the *true* detections that matter most: those that reach a robot whose
       belief has collapsed onto a wrong place, which cannot tell them from phantoms.

``identity`` = ``"withheld"`` handling (§7.2 "Identification of robots": the factorial
    representation "cannot deal with measurements such as 'either robot A or robot B'"): a
    detection with ``robot_id`` None is *associated by belief*. The observer broadcasts its tree
    as a query (``kind="assoc_query"``); every robot that hears it answers with the tree's
    density under its own belief, ``E_n = sum_i w_i tree(x_i)`` (one float). Two steps later
    (query out, answers back) the observer picks the robot with the largest ``E_n``, provided it beats the uniform
    density ``1 / A`` by ``assoc_min_ratio`` and the runner-up by ``assoc_margin``, and sends it
    the ordinary detection message (the tree it kept). Ambiguous detections (every robot still
    globally uncertain, or two robots equally plausible) are dropped. With ``anonymous="ignore"``
    the brain does what the paper's method does with anonymous sights: nothing.

``negative_detections`` (§7.2 "Not seeing each other"; :mod:`teamnav.control.negative_sights`)
    Not seeing a teammate where its broadcast belief says it should be visible weighs the own
    samples down, by a likelihood over the detector's range and field of view with line of sight
    on the known map (:mod:`teamnav.localization.negative_detection`). Off by default (§2.3 rule 1).

``unsure_detections`` (§7.2 "Delayed integration"; :mod:`teamnav.control.delayed_integration`)
    A detection made while unsure: sent at once (the paper's §3.2 rule, default), dropped, or
    delayed until the belief is concentrated and applied at its time by both robots.

``paper_rules=True`` is the paper as written (:attr:`MCLWanderParams.PAPER_RULES`,
:mod:`teamnav.control.paper_rules`; the reports' "paper as written" column): eq. 14 alone on a
received tree (no sensor resetting), the untempered likelihood (eq. 12), resampling at every
update (§3.1), §2.3's two rules only (no provenance, no gate on the receiving side), every
detection sent (§3.2), no false-positive filter, anonymous and negative sights ignored (§7.2, §2.3). Setting one
of those fields as well is an error. What the paper gives no value for is kept in both columns
and listed in :attr:`MCLWanderParams.GAP_FILLS_KEPT` (the KLD floor among them).

The filter never sees a true pose; experiments score it from what :meth:`MCLWander.log`
records (a weighted subsample of the particles every recorded step, see
:mod:`teamnav.experiments.metric_sets.localization`).
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from teamnav.control.delayed_integration import DelayedIntegration, past_frame, resolve_unsure_detections
from teamnav.control.nav.wander import Wander, WanderParams
from teamnav.control.negative_sights import NegativeSights
from teamnav.control.paper_rules import paper_rules_validator
from teamnav.control.protocol import RobotInfo
from teamnav.control.tree_injection import inject_tree
from teamnav.control.types import Action, Message, Observation
from teamnav.localization import (
    BeamModelParams, BeliefSync, DetectionModel, KLDParams, LikelihoodFieldParams, MCL, MCLParams, MotionParams,
    SyncMessage, SyncParams,
)
from teamnav.localization.density_tree import DensityTree
from teamnav.localization.resample import low_variance_kernel
from teamnav.localization.sync import SYNC_KIND, detection_tree
from teamnav.world.grid import DEFAULT_SEES, FREE

__all__ = ["MCLWander", "MCLWanderParams", "load_detection_model", "MODEL_DIR"]

#: Folder of the detection models shipped with teamnav (``detection_model: default`` is
#: ``MODEL_DIR / "detection-default.json"``).
MODEL_DIR: Path = Path(str(resources.files("teamnav.localization"))) / "models"

#: ``Message.kind`` of identity-association traffic.
ASSOC_KIND = "mcl_assoc"


def load_detection_model(name: str) -> DetectionModel:
    """A detection model by name (``MODEL_DIR/detection-NAME.json``) or by file path."""
    p = Path(name)
    if p.suffix.lower() != ".json":
        p = MODEL_DIR / f"detection-{name}.json"
    if not p.is_file():
        known = sorted(q.stem.removeprefix("detection-") for q in MODEL_DIR.glob("detection-*.json"))
        raise ValueError(f"detection_model must name a shipped model ({', '.join(known)}) or a .json file, "
                         f"got {name!r} (no file {p})")
    return DetectionModel.load(p)


@dataclass(frozen=True)
class _AssocQuery:
    """Broadcast: "whose belief fits this tree of the robot I saw?" (identity withheld)."""

    qid: int
    observer: int
    tree: DensityTree


@dataclass(frozen=True)
class _AssocAnswer:
    """Answer to :class:`_AssocQuery`: the tree's density under the answering robot's belief."""

    qid: int
    observer: int
    evidence: float


class MCLWanderParams(BaseModel):
    """Parameters of ``mcl-wander-v1`` (units in the names; see the module docstring).

    Attributes
    ----------
    sensor : str or None
        Range sensor used for localization and for avoiding obstacles (None: the first).
    wander : WanderParams
        The wanderer (cruise speed, wall following, ...).
    max_particles, min_particles : int
        KLD-sampling bounds (global initialisation draws ``max_particles``).
    adaptive : bool
        KLD-sampling on (else a fixed ``max_particles``).
    kld_epsilon : float
        KLD error bound.
    random_fraction : float
        Share of samples replaced per step by uniform ones (§3.1).
    sensor_model : {"beam", "likelihood_field"}
    beam, likelihood_field, motion
        Model parameters (the library's).
    beam_stride : int
        Use every n-th beam.
    likelihood_exponent : float
        Tempering of ``P(o | l)`` against correlated beams.
    resample_ess_fraction : float
        Resample only when the effective sample size ``1 / sum w²`` is below this share of
        the set (selective resampling, Doucet et al. 2000; 1: every update as in §3.1).
        Fewer resamplings keep the modes of a symmetric belief from dying out by drift.
    sonar_rays_per_cone : int
        Rays cast across a sonar cone by the filter (its expected range is their minimum).
    init_clearance_m : float
        Uniform samples only where the map's clearance is at least this [m] (the robot's
        body cannot be closer to a wall).
    min_update_m, min_update_deg : float
        Filter update (motion + scan) only once odometry accumulated this much motion; the
        odometry steps in between are composed into one (as AMCL's ``update_min_d``).
    motion_mode : {"wander", "stay"}
        Wander, or stand still (Marian in §5.1 "operating in the lab facing towards the
        opening of the hallway").
    init_pose : (x_m, y_m, theta_deg) or None
        None: global localization (uniform over free space); else position tracking from a
        known start, a Gaussian of ``init_std_m`` / ``init_std_deg`` (the paper's training
        runs and its localized robot in §5.1 start so).
    collaborate : bool
        Synchronise beliefs on detections (§3.2); False: single-robot MCL.
    send_min_cluster_weight : float
        A belief is *concentrated* when its heaviest cluster holds at least this weight and is no
        wider than ``send_max_cluster_spread_m`` (declared thresholds; §7.2 says "highly uncertain"
        only). 0 (default): always (§3.2). > 0 alone means ``unsure_detections="drop"`` (the earlier
        behaviour).
    send_max_cluster_spread_m : float or None
        The heaviest cluster's position spread ``sqrt(var x + var y)`` must be at most this [m] for a
        concentrated belief (gap-fill, session 17). None: the weight alone, the definition of
        sessions 15-16, which called a lost robot's uniform belief concentrated (one connected
        cluster of weight 1 once the samples fill the free space: 2000 or more in the hallway), so
        "drop" and "delay" sent a lost robot's detections at once. Inert with
        ``send_min_cluster_weight`` 0.
    unsure_detections : {"integrate", "drop", "delay"}
        A detection made while the observer's belief is not concentrated is sent at once
        (``"integrate"``, default, §3.2), dropped, or kept and sent once it is, applied at the
        detection's time by both robots (``"delay"``, §7.2; :mod:`teamnav.control.delayed_integration`,
        which also says which settings conflict).
    delay_max_age_s : float
        ``"delay"``: stored detections older than this are dropped [s] (gap-fill, no value in the paper).
    inject_fraction : float
        Beyond the paper: on a received detection tree, this share of the samples is first
        replaced by draws from the tree (uniform heading) before eq. 14 reweights them all
        (:meth:`MCL.replace_samples`: sensor resetting). 0 (default): pure eq. 14. Needed
        with our sample sets (thousands, not the paper's "very large" ones) when the belief
        has no sample near the detected position.
    inject_weighting : {"bayes", "tree"}
        How much weight the draws get (:meth:`MCLWander._inject_and_apply`). ``"tree"``: the
        set's mean weight, then eq. 14 (measured: a receiver whose belief the tree contradicts
        adopts the sender's belief, right or wrong; in the hexagon a confidently wrong robot
        dragged localized teammates to its mode). ``"bayes"`` (default): the share of the
        posterior that the receiver is lost, under the prior ``inject_lost_prior``.
    inject_lost_prior : float
        Prior probability that the receiver's belief is wrong (``"bayes"`` weighting).
    inject_heading_belief_share : float
        Share of the draws whose heading comes from the own belief (a sample drawn by weight,
        plus ``inject_heading_std_deg`` of noise); the rest get a uniform heading (0: all
        uniform, the first version). A detection sees the position only; with uniform
        headings the draws in a featureless corridor include the mirror pose (other side of
        the axis, heading reversed) that the scan cannot tell apart, and it won in one of 10
        §5.1 runs (Robin then drove "west" while it went east: error 23 m).
    inject_heading_std_deg : float
        Heading noise of those draws [deg].
    inject_heading_scan_share : float
        Share of the remaining draws (those without a belief heading) whose heading is picked
        by the current scan: ``inject_heading_candidates`` headings on a jittered grid are
        scored with the sensor model at the drawn position and one is drawn in proportion to
        the (tempered) likelihood; the rest keep a uniform heading. 0 (default): the first
        version (uniform). Beyond the paper, measured in the symmetric hallway: a confidently
        wrong receiver there sits on a *rotated* place (hallways B, C, D look alike), so its own
        heading is wrong by 90° or 180° and of uniform headings only a few percent fit the
        corridor; those draws lose to the kept wrong mode within a few scans even when the
        sender is right (3 of 5 right-sender trees reaching a wrong receiver, seed 2). The scan
        already weighted the kept samples; using it again for the draws' heading only chooses
        where among the draws' poses to look (the draws' share stays the Bayes share).
    inject_heading_candidates : int
        Headings scored per draw for ``inject_heading_scan_share``.
    inject_min_draws : int
        At least this many draws (``"bayes"`` weighting): when ``inject_fraction`` of the set
        is fewer, the draws are *added* to the set (:meth:`MCL.append_samples`) instead of
        replacing samples. 0 (default): ``inject_fraction`` of the set, the first version.
        Beyond the paper, measured in the symmetric hallway: a confidently wrong robot carries
        only the KLD minimum (500 samples), so a right sender's tree became 50 draws; the
        draws got the Bayes share (92 %) but were too few to cover the tree's metre of
        position and the heading, and the kept wrong mode, matching every scan, won back
        within 10-30 s (4 of 10 right-sender trees reaching a confidently wrong robot, seed 0).
    inject_sender_lost_prior : float
        Prior probability that the *sender's* belief is wrong (``"bayes"`` weighting). The
        first version weighs "I am lost" against a false-positive detection only, as if the
        sender were always right: a tree that contradicts a confident belief gives the draws
        ``eps / (eps + (1 - eps) p_fp)`` = 92 % of the weight, whoever is wrong. Under "the
        sender is lost" the tree says nothing about the receiver, so it joins the false
        positive in the uniform floor: ``f = (1 - p_fp)(1 - eps_s) tree + (p_fp + (1 - p_fp)
        eps_s) / A``; with ``eps_s = eps`` = 0.3 a disagreement between two confident robots
        splits the receiver about 57 / 43 and both modes stay until a scan or a third robot
        decides. 0 (default): the first version. Beyond the paper (eq. 10 treats the sender's
        belief as exact), measured in the symmetric hallway: 15 applied trees from confidently
        wrong senders flipped confidently right receivers in one run (seed 0); the places are
        rotated copies of each other, so the receivers' scans could not undo it.
    inject_before_reply : bool
        The first version drew the samples *before* building the reply tree of §2.3, so the
        reply carried ``inject_fraction`` of the sender's own tree back to it and the sender
        multiplied its own belief in again (double counting: a confidently wrong sender was
        confirmed by the teammate it had just dragged along). False (default): the reply is
        built from the belief as it was before the message.
    negative_detections : bool
        Beyond the paper (§7.2 future work; issue 22): on a camera frame that does not see teammate n,
        weigh each own sample by the probability of not seeing n from it, given the points of n's
        belief that n broadcast (:mod:`teamnav.control.negative_sights`, the likelihood
        :mod:`teamnav.localization.negative_detection`). False (default): §2.3 rule 1, negative
        sights ignored. Needs ``collaborate``.
    neg_points : int
        Points of its belief a concentrated robot broadcasts before each camera frame.
    neg_max_spread_m : float
        A robot broadcasts only while its belief's position spread ``sqrt(var x + var y)`` is at most
        this [m] (gap-fill; the heaviest cluster's weight is no test here: a uniform belief over a
        connected free space is one cluster of 0.5 m cells, weight 1).
    neg_when_concentrated : bool
        False (default, gap-fill): the observer uses negative sights only while its own belief is *not*
        concentrated (spread above ``neg_max_spread_m``); True: always. Measured on tuning seed 1000 in
        the hallway: a localized robot's samples all see a confidently wrong teammate's claimed place
        alike, so each miss multiplies only its few uniform recovery samples up (x 6 per miss), and a
        few misses in a row moved a right robot off (final error 18 m; 0.2 m without negative sights).
    neg_teammate_lost_prior : float
        Probability that the teammate's belief is wrong (the factor becomes ``1 - (1 - p_fn)(1 -
        eps) P_vis``; 0: the plain marginal).
    neg_min_travel_m : float
        §2.3 rule 2 for negative sights: one use of a teammate per this much own travel [m].
    neg_max_age_s : float
        Teammate points older than this are not used [s].
    neg_max_range_m, neg_fov_deg, neg_sees
        The detector's datasheet as the brain knows it: range centre to centre [m], field of view
        [deg] and the materials that hide a robot (defaults: the collaborative scenarios' detector).
    receive_gate : bool
        Rule 2 of §2.3 applied on the receiving side too (:class:`~teamnav.localization.SyncParams`):
        a tree from a given teammate is applied at most once per ``min_travel_m`` of own travel
        (beyond the paper; False: the paper's rule, which gates the detecting robot only).
    provenance : bool
        Rule 2 of §2.3 made transitive (:class:`~teamnav.localization.SyncParams`): a tree that
        holds this robot's own information from less than ``min_travel_m`` ago, passed on by a
        third robot, is dropped (beyond the paper; False: the paper's rules only).
    detection_model : str
        Shipped model name or a path to a model file (:func:`load_detection_model`).
    detection_period_s : float
        Camera frame period: detections are looked at once per period [s].
    min_travel_m : float
        §2.3 rule 2.
    tree_min_samples, tree_max_depth : int
        Density-tree stopping rule.
    false_positive_filter : bool
        The three gates of the module docstring.
    fp_min_free_mass, fp_confirm_window_s, fp_confirm_gate_m, fp_min_real_prob
        Their thresholds.
    anonymous : {"associate", "ignore"}
        What to do with detections without identity.
    assoc_min_ratio, assoc_margin : float
        Association thresholds.
    parallel : bool
        Let the filter's kernels use numba threads (off by default: a team runs one filter per
        robot, and on busy cores a thread launch costs more than a serial update).
    log_points : int
        Particles (drawn by weight) logged every recorded step for scoring.
    layer_every : int
        Every this many log() calls, a ``particles`` layer of ``layer_points`` for the replay.
    paper_rules : bool
        Every gap-fill of :attr:`PAPER_RULES` at the paper's value
        (:mod:`teamnav.control.paper_rules`); setting one of them as well is an error.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    #: the gap-fills whose other value is the paper's rule (Fox, Burgard, Kruppa & Thrun 2000)
    PAPER_RULES: ClassVar[dict[str, Any]] = {
        # §3.2, eq. 14: "These density values are then multiplied into each individual sample <l, p>
        # of the detected robot": the received tree only reweights the samples there are
        "inject_fraction": 0.0,
        # §3.2, eq. 14: no draws from the tree, so no minimum number of them either
        "inject_min_draws": 0,
        # §2.3, eq. 10: the sender's belief enters as it is (no prior that the sender is wrong)
        "inject_sender_lost_prior": 0.0,
        # §3.1, eq. 12: "p <- alpha P(o | l)" (the perception model untempered)
        "likelihood_exponent": 1.0,
        # §3.1 step 1: "When a robot moves, MCL generates K new samples ... by randomly drawing a
        # sample from the previously computed sample set": a resampling at every update
        "resample_ess_fraction": 1.0,
        # §2.3: "our approach uses the following two rules" (rule 2 not made transitive)
        "provenance": False,
        # §2.3 rule 2: "blocks the ability to see the same robot again until the *detecting* robot
        # has traveled a prespecified distance": no gate on the receiving side
        "receive_gate": False,
        # §3.2: "When one robot detects another, both sample sets are synchronized" (every detection)
        "send_min_cluster_weight": 0.0,
        # §3.2 / Table 1: "if the robot is detected by the m-th robot do ... apply the detection model"
        # at once; §7.2's delayed integration is a suggestion for future work
        "unsure_detections": "integrate",
        # §7.2: false positives were "not modeled"; "Our sample-based implementation ... is not robust"
        "false_positive_filter": False,
        # §7.2: "The factorial representation, however, cannot deal with measurements such as
        # 'either robot A or robot B'": sights without identity are not used
        "anonymous": "ignore",
        # §2.3 rule 1: "Our approach ignores *negative* sights"; §7.2 lists them as future work
        "negative_detections": False,
    }
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {
        "inject_fraction": "Fox §3.2 eq. 14: the tree only reweights the existing samples (no sensor resetting)",
        "inject_min_draws": "Fox §3.2 eq. 14: no draws from the tree",
        "inject_sender_lost_prior": "Fox §2.3 eq. 10: the sender's belief is used as it is",
        "likelihood_exponent": "Fox §3.1 eq. 12: p <- alpha P(o | l), untempered",
        "resample_ess_fraction": "Fox §3.1: K new samples drawn at every motion update",
        "provenance": "Fox §2.3: the two rules only (rule 2 not transitive)",
        "receive_gate": "Fox §2.3 rule 2: only the detecting robot waits 2.5 m",
        "send_min_cluster_weight": "Fox §3.2: every detection synchronises both beliefs",
        "unsure_detections": "Fox §3.2, Table 1: a detection is integrated at once (§7.2's delay is future work)",
        "false_positive_filter": "Fox §7.2: false positives not filtered",
        "anonymous": "Fox §7.2: sights without identity are not used",
        "negative_detections": "Fox §2.3 rule 1: negative sights are ignored (§7.2: future work)",
    }
    #: gap-fills the paper gives no value for: the same value in both columns (field: why)
    GAP_FILLS_KEPT: ClassVar[dict[str, str]] = {
        "min_particles": "KLD floor: §3.1 adapts the sample count on the fly (Fox et al. 1999a) and gives no "
                         "floor and no counts for its experiments",
        "max_particles": "§3.1 global localization uses many samples; no count is given",
        "random_fraction": "§3.1 'a small number of uniformly distributed, random samples'; no number",
        "min_update_m": "the paper updates on each odometry reading and scan; no rate is given",
        "min_update_deg": "as min_update_m",
        "beam": "Fig. 1's mixture; its weights and widths are not given (ours: the simulated sensor's)",
        "motion": "Fig. 2's motion model; its noise is not given",
        "tree_min_samples": "§3.2's stopping rule 'see Thrun et al. (1999b)'; no value",
        "inject_lost_prior": "inert with inject_fraction 0 (the paper's), as are inject_weighting and the "
                             "inject_heading_* settings",
        "delay_max_age_s": "inert with unsure_detections 'integrate' (the paper's)",
        "send_max_cluster_spread_m": "inert with send_min_cluster_weight 0 (the paper's)",
        "wander": "§5: the robots follow an operator or a random walk; our wanderer's settings",
        "neg_points": "inert with negative_detections false (the paper's), as are the other neg_* settings",
    }

    sensor: str | None = Field(None, min_length=1)
    wander: WanderParams = WanderParams(cruise_speed_mps=0.3, turn_rate_radps=0.8)
    max_particles: int = Field(5000, ge=10, le=1_000_000)
    min_particles: int = Field(300, ge=10, le=1_000_000)
    adaptive: bool = True
    kld_epsilon: float = Field(0.05, gt=0.0, le=1.0)
    random_fraction: float = Field(0.005, ge=0.0, le=0.5)
    sensor_model: Literal["beam", "likelihood_field"] = "beam"
    beam: BeamModelParams = BeamModelParams(z_hit=0.7, z_short=0.1, z_max=0.1, z_rand=0.1, sigma_hit_m=0.2)
    likelihood_field: LikelihoodFieldParams = LikelihoodFieldParams()
    motion: MotionParams = MotionParams(alpha=(0.1, 0.05, 0.05, 0.05))
    beam_stride: int = Field(1, ge=1, le=64)
    likelihood_exponent: float = Field(0.5, gt=0.0, le=1.0)
    resample_ess_fraction: float = Field(0.5, gt=0.0, le=1.0)
    sonar_rays_per_cone: int = Field(3, ge=1, le=64)
    init_clearance_m: float = Field(0.2, ge=0.0, le=10.0)
    min_update_m: float = Field(0.2, ge=0.0, le=10.0)
    min_update_deg: float = Field(15.0, ge=0.0, le=360.0)
    motion_mode: Literal["wander", "stay"] = "wander"
    init_pose: tuple[float, float, float] | None = None
    init_std_m: float = Field(0.3, gt=0.0, le=100.0)
    init_std_deg: float = Field(10.0, gt=0.0, le=360.0)
    collaborate: bool = False
    send_min_cluster_weight: float = Field(0.0, ge=0.0, le=1.0)
    send_max_cluster_spread_m: float | None = Field(2.0, gt=0.0, le=1000.0)
    unsure_detections: Literal["integrate", "drop", "delay"] = "integrate"
    delay_max_age_s: float = Field(60.0, gt=0.0, le=3600.0)
    inject_fraction: float = Field(0.0, ge=0.0, le=0.5)
    inject_weighting: Literal["bayes", "tree"] = "bayes"
    inject_lost_prior: float = Field(0.3, gt=0.0, lt=1.0)
    inject_heading_belief_share: float = Field(0.5, ge=0.0, le=1.0)
    inject_heading_std_deg: float = Field(10.0, ge=0.0, le=180.0)
    inject_heading_scan_share: float = Field(0.0, ge=0.0, le=1.0)
    inject_heading_candidates: int = Field(12, ge=2, le=360)
    inject_min_draws: int = Field(0, ge=0, le=1_000_000)
    inject_sender_lost_prior: float = Field(0.0, ge=0.0, lt=1.0)
    inject_before_reply: bool = False
    provenance: bool = True
    detection_model: str = Field("default", min_length=1)
    detection_period_s: float = Field(1.0, ge=0.0, le=60.0)
    min_travel_m: float = Field(2.5, ge=0.0, le=1000.0)
    tree_min_samples: int = Field(20, ge=1, le=100_000)
    tree_max_depth: int = Field(20, ge=1, le=64)
    false_positive_filter: bool = False
    fp_min_free_mass: float = Field(0.5, ge=0.0, le=1.0)
    fp_confirm_window_s: float = Field(2.5, gt=0.0, le=60.0)
    fp_confirm_gate_m: float = Field(1.5, gt=0.0, le=100.0)
    fp_min_real_prob: float = Field(0.0, ge=0.0, le=1.0)
    anonymous: Literal["associate", "ignore"] = "associate"
    assoc_min_ratio: float = Field(0.0, ge=0.0, le=1e9)
    assoc_margin: float = Field(3.0, ge=1.0, le=1e9)
    parallel: bool = False
    log_points: int = Field(64, ge=1, le=1000)
    layer_every: int = Field(20, ge=1, le=100_000)
    layer_points: int = Field(200, ge=1, le=1000)
    receive_gate: bool = True
    negative_detections: bool = False
    neg_points: int = Field(24, ge=1, le=1000)
    neg_max_spread_m: float = Field(1.0, gt=0.0, le=1000.0)
    neg_when_concentrated: bool = False
    neg_teammate_lost_prior: float = Field(0.1, ge=0.0, lt=1.0)
    neg_min_travel_m: float = Field(2.5, ge=0.0, le=1000.0)
    neg_max_age_s: float = Field(1.5, gt=0.0, le=60.0)
    neg_max_range_m: float = Field(5.0, gt=0.0, le=1000.0)
    neg_fov_deg: float = Field(180.0, gt=0.0, le=360.0)
    neg_sees: tuple[str, ...] = Field(DEFAULT_SEES["vision"], min_length=1)
    paper_rules: bool = False

    _paper_rules = paper_rules_validator()

    @model_validator(mode="after")
    def _unsure_detections(self) -> "MCLWanderParams":
        return resolve_unsure_detections(self)

    @model_validator(mode="after")
    def _negative_needs_team(self) -> "MCLWanderParams":
        if self.negative_detections and not self.collaborate:
            raise ValueError("negative_detections: true needs collaborate: true (teammates' beliefs come "
                             "over the radio of the collaborative brain)")
        return self

    def mcl_params(self) -> MCLParams:
        """The library's filter parameters these stand for."""
        return MCLParams(
            n_particles=self.max_particles, sensor_model=self.sensor_model, beam=self.beam,
            likelihood_field=self.likelihood_field, motion=self.motion, beam_stride=self.beam_stride,
            likelihood_exponent=self.likelihood_exponent, recovery="fixed" if self.random_fraction > 0 else "none",
            random_fraction=self.random_fraction, adaptive=self.adaptive,
            kld=KLDParams(epsilon=self.kld_epsilon, min_particles=min(self.min_particles, self.max_particles),
                          max_particles=self.max_particles),
            sonar_rays_per_cone=self.sonar_rays_per_cone, init_clearance_m=self.init_clearance_m,
            parallel=self.parallel,
        )


def _to_odom(odom_pose: np.ndarray, range_m: float, bearing_rad: float) -> np.ndarray:
    """A detection's point in the observer's odometry frame."""
    a = float(odom_pose[2]) + bearing_rad
    return np.array([odom_pose[0] + range_m * math.cos(a), odom_pose[1] + range_m * math.sin(a)])


class MCLWander:
    """``mcl-wander-v1``: wander and localize, optionally with the team (see the module docstring).

    Parameters
    ----------
    params : MCLWanderParams
    rng : numpy.random.Generator
    info : RobotInfo
        Must carry ``known_map`` (scenario ``give_map: true``) and the range sensor.
    """

    Params = MCLWanderParams
    #: check_brain gives it a small known map (it needs one, like a scenario with give_map: true)
    needs_map = True

    def __init__(self, params: MCLWanderParams, rng: np.random.Generator, info: RobotInfo) -> None:
        if not isinstance(params, MCLWanderParams):
            raise ValueError(f"params must be an MCLWander.Params, got {type(params).__name__}")
        if info.known_map is None:
            raise ValueError(f"robot {info.robot_id}: mcl-wander-v1 needs a map; set 'give_map: true' in the scenario")
        self.params = params
        self.info = info
        self.robot_id = int(info.robot_id)
        self.rng = rng
        self.wander = Wander(params.wander.model_copy(update={"sensor": params.sensor}), rng, info)
        self.sensor = info.sensors[self.wander.sensor]
        self.mcl = MCL(params.mcl_params(), info.known_map, self.sensor, rng)
        if params.init_pose is None:
            self.mcl.init_global()
        else:
            x, y, th = params.init_pose
            self.mcl.init_pose([x, y, math.radians(th)], np.diag([params.init_std_m ** 2, params.init_std_m ** 2,
                                                                  math.radians(params.init_std_deg) ** 2]))
        self.model = load_detection_model(params.detection_model) if params.collaborate else None
        self.sync = (BeliefSync(self.robot_id, self.model, SyncParams(min_travel_m=params.min_travel_m,
                                                                      tree_min_samples=params.tree_min_samples,
                                                                      tree_max_depth=params.tree_max_depth,
                                                                      provenance=params.provenance,
                                                                      receive_gate=params.receive_gate), rng)
                     if params.collaborate else None)
        self._free = (info.known_map.cells == FREE)
        self._next_frame_s = 0.0
        self._last_seen: dict[Any, tuple[float, np.ndarray]] = {}  # id -> (time, point in odom frame)
        self._pending: dict[int, dict] = {}  # association queries: query id -> {"tree", "det", "scores", "t"}
        self._query_seq = 0
        self._odom = np.zeros(3)
        self._scan: np.ndarray | None = None  # this step's ranges (scan-picked headings of draws)
        self._acc = np.zeros(3)  # odometry composed since the last filter update
        self._stepped = False
        self._min_rot = math.radians(params.min_update_deg)
        self._n_log = 0
        self._time_s = 0.0
        #: one record per detection tree received (time, sender, the belief's sample count, spread and
        #: heaviest cluster's weight just before it, whether it was applied); logged as "det_belief"
        self._det_log: list[dict[str, Any]] = []
        self._det_logged = 0
        #: Counters for logs: detections seen / sent, phantoms filtered, messages dropped, associations.
        self.stats = {"seen": 0, "sent": 0, "filtered": 0, "rejected": 0, "assoc": 0, "assoc_dropped": 0}
        # §7.2 delayed integration: odometry history, detections kept while unsure
        self._delay = DelayedIntegration(params.delay_max_age_s, keep_history=params.collaborate)
        # §7.2 negative sights (issue 22): teammates' broadcast points and the rate rule
        self._neg = (NegativeSights(params, self.robot_id, info.known_map, self.model.p_false_negative, info.dt_s)
                     if params.negative_detections else None)

    # ------------------------------------------------------------------ step
    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Localize (motion + scan), apply teammates' messages, look for teammates, wander."""
        p = self.params
        self._odom = np.asarray(obs.odom_pose, dtype=float)
        self._time_s = float(obs.time_s)
        scan = obs.scans[self.wander.sensor]
        self._scan = np.asarray(scan.ranges_m, dtype=float)
        self._accumulate(np.asarray(obs.odom_delta, dtype=float))
        acc = self._acc
        filtered = False
        if not self._stepped or math.hypot(acc[0], acc[1]) >= p.min_update_m or abs(acc[2]) >= self._min_rot:
            self._filter_step(acc, scan.ranges_m)
            self._acc = np.zeros(3)
            self._stepped = True
            filtered = True
        self._delay.record(obs.time_s, self._odom, self._scan, filtered)
        out: list[Message] = []
        if self.sync is not None:
            self.sync.travel(obs.odom_delta)
            neg = self._neg
            if neg is not None:
                neg.travel(obs.odom_delta)
            for msg in obs.inbox:
                if neg is None or not neg.on_message(msg, obs.time_s):
                    out += self._on_message(msg, obs)
            if obs.time_s + 1e-9 >= self._next_frame_s:
                self._next_frame_s = obs.time_s + p.detection_period_s
                out += self._on_detections(obs)
                if neg is not None:
                    neg.on_frame(self.mcl, obs.detections, obs.time_s)
            out += self._close_queries(obs)
            if neg is not None:
                out += neg.broadcast(self.mcl, self.rng, obs.time_s, self._next_frame_s)
        action, _ = self.wander.step(obs)
        if p.motion_mode == "stay":
            action = Action.stop()
        return action, out

    def _filter_step(self, odom_delta: np.ndarray, ranges: np.ndarray) -> None:
        """Resample (only when the effective sample size fell below ``resample_ess_fraction``
        of the set), predict, weight: :meth:`MCL.step` with selective resampling."""
        w = self.mcl.weights
        if self._stepped and 1.0 / float(np.dot(w, w)) < self.params.resample_ess_fraction * w.shape[0]:
            self.mcl.resample()
        self.mcl.predict(odom_delta)
        self.mcl.update(ranges)

    def _accumulate(self, d: np.ndarray) -> None:
        """Compose this step's odometry ``d`` (previous body frame) onto the pending motion."""
        a = self._acc
        c, s_ = math.cos(a[2]), math.sin(a[2])
        th = a[2] + d[2]
        self._acc = np.array([a[0] + c * d[0] - s_ * d[1], a[1] + s_ * d[0] + c * d[1],
                              math.atan2(math.sin(th), math.cos(th))])

    # ------------------------------------------------------------------ detections
    def _free_mass(self, det) -> float:
        """Weight of the observer's belief that puts the detected robot in free space (gate 1)."""
        pos = self.model.sample_positions(self.mcl.particles, det.range_m, det.bearing_rad, self.rng)
        g = self.info.known_map
        iy, ix = np.moveaxis(g.world_to_cell(pos[:, :2]), -1, 0)  # the map's own transform (any yaw)
        h, w = self._free.shape
        inside = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
        ok = np.zeros(pos.shape[0], dtype=bool)
        ok[inside] = self._free[iy[inside], ix[inside]]
        return float(np.dot(self.mcl.weights, ok))

    def _confirmed(self, key, det, t_s: float) -> bool:
        """Gate 2: the same robot seen on a recent frame at a consistent place (odometry frame)."""
        pt = _to_odom(self._odom, det.range_m, det.bearing_rad)
        prev = self._last_seen.get(key)
        self._last_seen[key] = (t_s, pt)
        if prev is None or t_s - prev[0] > self.params.fp_confirm_window_s:
            return False
        return bool(np.hypot(*(pt - prev[1])) <= self.params.fp_confirm_gate_m)

    def _on_detections(self, obs: Observation) -> list[Message]:
        p = self.params
        out: list[Message] = []
        keep = []
        for det in obs.detections:
            self.stats["seen"] += 1
            if det.robot_id is not None and det.robot_id == self.robot_id:
                continue
            if p.false_positive_filter:
                key = det.robot_id if det.robot_id is not None else ("anon", self._anon_key(det))
                if not self._confirmed(key, det, obs.time_s) or self._free_mass(det) < p.fp_min_free_mass:
                    self.stats["filtered"] += 1
                    continue
            keep.append(det)
        if p.unsure_detections != "integrate" and not self._concentrated():
            if p.unsure_detections == "delay":  # §7.2: keep the named ones for later
                self._delay.keep(keep, obs.time_s)
            return out
        named = [d for d in keep if d.robot_id is not None]
        if named:
            msgs = self.sync.on_detections(self.mcl, named, obs.time_s)
            self.stats["sent"] += len(msgs)
            out += msgs
        if p.unsure_detections == "delay" and len(self._delay.store):
            msgs = self._delay.send_stored(self.sync, self.mcl, obs.time_s, self._past)
            self.stats["sent"] += len(msgs)
            out += msgs
        if p.anonymous == "associate":
            for det in keep:
                if det.robot_id is None:
                    out += self._query(det, obs)
        return out

    def _concentrated(self) -> bool:
        """§7.2's "more certain", as declared by ``send_min_cluster_weight`` and
        ``send_max_cluster_spread_m`` (gap-fills: the heaviest cluster is heavy *and* narrow)."""
        p, est = self.params, self.mcl.estimate()
        if est.cluster_weight < p.send_min_cluster_weight:
            return False
        return p.send_max_cluster_spread_m is None or est.cluster_spread_m <= p.send_max_cluster_spread_m

    # ------------------------------------------------------------------ §7.2 delayed integration
    @contextmanager
    def _past(self, t_s: float, motion: np.ndarray):
        """The samples (and the scan the draws' headings use) as they were at time ``t_s``, and back."""
        saved = self._scan
        self._scan = self._delay.history.scan_at(t_s)
        try:
            with past_frame(self.mcl, motion):
                yield
        finally:
            self._scan = saved

    def _anon_key(self, det) -> int:
        """Anonymous detections are matched to the previous frame's nearest one (gate 2)."""
        pt = _to_odom(self._odom, det.range_m, det.bearing_rad)
        best, best_d = None, math.inf
        for key, (_, q) in self._last_seen.items():
            if isinstance(key, tuple) and key[0] == "anon":
                d = float(np.hypot(*(pt - q)))
                if d < best_d:
                    best, best_d = key[1], d
        if best is not None and best_d <= self.params.fp_confirm_gate_m:
            return best
        self._query_seq += 1
        return -self._query_seq

    # ------------------------------------------------------------------ identity by belief
    def _query(self, det, obs: Observation) -> list[Message]:
        """Broadcast the detection tree; teammates answer with its density under their beliefs."""
        if not self.sync.detect_gate.allowed(-1):  # one anonymous use per min_travel_m
            return []
        tree = detection_tree(self.mcl.particles, self.mcl.weights, det.range_m, det.bearing_rad, self.model,
                              self.rng, self.sync.params)
        self._query_seq += 1
        qid = self._query_seq
        self._pending[qid] = {"tree": tree, "det": det, "scores": {}, "step": obs.step}
        return [Message(self.robot_id, float(obs.time_s), _AssocQuery(qid, self.robot_id, tree), to=None,
                        kind=ASSOC_KIND)]

    def _close_queries(self, obs: Observation) -> list[Message]:
        """Pick the robot an anonymous detection was of, once the answers are in.

        The query reaches the others one step after it is sent and their answers come back one
        step later still, so a query is closed two steps after it was sent.
        """
        out: list[Message] = []
        p = self.params
        for qid in [q for q, v in self._pending.items() if obs.step >= v["step"] + 2]:
            pend = self._pending.pop(qid)
            scores = sorted(pend["scores"].items(), key=lambda kv: -kv[1])
            uniform = 1.0 / self.mcl.free_area_m2
            if not scores or scores[0][1] < p.assoc_min_ratio * uniform or (
                    len(scores) > 1 and not scores[0][1] > p.assoc_margin * scores[1][1]):
                self.stats["assoc_dropped"] += 1
                continue
            rid = int(scores[0][0])
            if not self.sync.detect_gate.allowed(rid):
                continue
            det = pend["det"]
            body = SyncMessage("detection", self.robot_id, rid, float(det.range_m), float(det.bearing_rad),
                               float(self.model.p_false_positive), pend["tree"], self.sync.outgoing_sources())
            out.append(Message(self.robot_id, float(obs.time_s), body, to=rid, kind=SYNC_KIND))
            self.sync.detect_gate.use(rid)
            self.sync.detect_gate.use(-1)
            self.stats["assoc"] += 1
            self.stats["sent"] += 1
        return out

    # ------------------------------------------------------------------ messages
    def _evidence(self, tree) -> float:
        """``E = sum_i w_i tree(x_i)``: the tree's density under this robot's belief [1/m²]."""
        return float(np.dot(self.mcl.weights, tree(self.mcl.particles[:, :2])))

    def _on_message(self, msg: Message, obs: Observation) -> list[Message]:
        """Handle one message; a tree of a delayed detection (§7.2, ``SyncMessage.detected_s``) is
        applied to the samples moved back to the detection's time, then moved forward again."""
        body = msg.body
        if isinstance(body, SyncMessage) and body.detected_s is not None and (
                (body.kind == "detection" and body.target == self.robot_id)
                or (body.kind == "inverse" and body.observer == self.robot_id)):
            motion = self._delay.motion_since(body.detected_s)
            if motion is None:  # older than this robot's history: cannot be applied retrospectively
                self.stats["stale"] = self.stats.get("stale", 0) + 1
                return []
            with self._past(body.detected_s, motion):
                return self._on_message_now(msg, obs)
        return self._on_message_now(msg, obs)

    def _on_message_now(self, msg: Message, obs: Observation) -> list[Message]:
        """Handle one message; a detection tree addressed to this robot is logged with the belief it
        met (issue 26 §2: the paper's Fig. 10a shows that belief still spread along the corridor)."""
        body = msg.body
        if not (msg.kind == SYNC_KIND and isinstance(body, SyncMessage) and body.kind == "detection"
                and body.target == self.robot_id):
            return self._handle(msg, obs)
        est = self.mcl.estimate()
        before = self.sync.applied["detection"]
        out = self._handle(msg, obs)
        self._det_log.append({"t_s": round(float(obs.time_s), 2), "from": int(body.observer),
                              "n_particles": int(est.n_particles),
                              "spread_m": round(float(math.sqrt(max(0.0, est.cov[0, 0] + est.cov[1, 1]))), 3),
                              "cluster_weight": round(float(est.cluster_weight), 3),
                              "applied": bool(self.sync.applied["detection"] > before)})
        return out

    def _handle(self, msg: Message, obs: Observation) -> list[Message]:
        p = self.params
        body = msg.body
        if msg.kind == ASSOC_KIND:
            if isinstance(body, _AssocQuery) and body.observer != self.robot_id:
                return [Message(self.robot_id, float(obs.time_s), _AssocAnswer(body.qid, body.observer,
                                                                                self._evidence(body.tree)),
                                to=body.observer, kind=ASSOC_KIND)]
            if isinstance(body, _AssocAnswer) and body.observer == self.robot_id and body.qid in self._pending:
                self._pending[body.qid]["scores"][msg.sender] = body.evidence
            return []
        if msg.kind != SYNC_KIND or not isinstance(body, SyncMessage):
            return []
        if p.false_positive_filter and body.kind == "detection" and body.target == self.robot_id:
            e = self._evidence(body.tree)
            pf = body.p_false_positive
            real = (1 - pf) * e / ((1 - pf) * e + pf / self.mcl.free_area_m2) if pf > 0 else 1.0
            if real < p.fp_min_real_prob:
                self.stats["rejected"] += 1
                return []
        if (p.inject_fraction > 0 and body.kind == "detection" and body.target == self.robot_id
                and self.sync.receive_allowed(body.observer)):
            return self._inject_and_apply(msg, obs)
        return self.sync.on_message(self.mcl, msg, obs.time_s)

    def _inject_and_apply(self, msg: Message, obs: Observation) -> list[Message]:
        """Apply a detection tree with sensor resetting; the reply (§2.3 symmetry) carries the
        belief from before the draws unless ``inject_before_reply`` (the first version)."""
        if self.params.inject_before_reply:
            factors = self._inject(self.mcl, msg.body)
            return self.sync.on_message(self.mcl, msg, obs.time_s, evidence=lambda mcl, body: factors)
        return self.sync.on_message(self.mcl, msg, obs.time_s, evidence=self._inject)

    def _inject(self, mcl: MCL, body: SyncMessage) -> np.ndarray:
        """Sensor resetting on a received tree, then eq. 14: :func:`~teamnav.control.tree_injection.inject_tree`."""
        return inject_tree(self.params, self.rng, self._scan, mcl, body)

    # ------------------------------------------------------------------ logs
    def _subsample(self, k: int) -> np.ndarray:
        """``k`` particles drawn by weight (low-variance), so their plain mean is the weighted one."""
        w = self.mcl.weights
        k = min(k, w.shape[0])
        idx = low_variance_kernel(w, k, float(self.rng.random()), np.empty(k, dtype=np.int64))
        return self.mcl.particles[idx]

    def log(self) -> dict[str, Any]:
        """Belief summary every recorded step; a particle layer every ``layer_every`` calls.

        ``pts``: ``log_points`` particles drawn by weight, flattened ``[x0, y0, x1, y1, ...]`` [m]
        rounded to cm: the metric's estimate of the paper's "average distance of all samples
        from the reference position" (§5.1) is their mean distance to the true position.
        """
        p = self.params
        est = self.mcl.estimate()
        sub = self._subsample(p.log_points)
        out: dict[str, Any] = {
            "est_x": round(float(est.cluster_pose[0]), 3),
            "est_y": round(float(est.cluster_pose[1]), 3),
            "est_th": round(float(est.cluster_pose[2]), 3),
            "n_particles": int(est.n_particles),
            "spread_m": round(float(math.sqrt(max(0.0, est.cov[0, 0] + est.cov[1, 1]))), 3),
            "syncs": int(sum(self.sync.applied.values())) if self.sync is not None else 0,
            "looped": int(self.sync.looped) if self.sync is not None else 0,
            "pts": [round(float(v), 2) for v in sub[:, :2].ravel()],
        }
        if len(self._det_log) > self._det_logged:
            out["det_belief"] = self._det_log[self._det_logged:]
            self._det_logged = len(self._det_log)
        if self._n_log == 0:
            out["sensor_kind"] = self.sensor.kind
            out["group"] = str(self.info.extras.get("group", ""))
        if self.sync is not None and self._n_log % p.layer_every == 0:
            out.update({k: v for k, v in self.stats.items()})
            if p.unsure_detections == "delay":
                out.update(self._delay.stats)
            if self._neg is not None:
                out.update(self._neg.stats)
        if self._n_log % p.layer_every == 0:
            pts = self._subsample(p.layer_points)[:, :2].astype(np.float32)
            out["layers"] = {"particles": {"data": pts, "kind": "points", "frame": "world", "hold": True,
                                           "description": "MCL samples (drawn by weight), map frame"}}
        self._n_log += 1
        return out
