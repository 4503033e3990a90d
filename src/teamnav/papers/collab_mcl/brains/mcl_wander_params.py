"""The parameters of ``mcl-wander-v1`` (:class:`~teamnav.papers.collab_mcl.brains.localizing.MCLWander`), field by field.

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization", Autonomous Robots 8(3), 2000. :class:`MCLWanderParams` holds

- the filter's settings (§3.1: sample counts and KLD-sampling, the perception and motion
  models of Figs. 1 and 2, uniform random samples, resampling) and :meth:`MCLWanderParams.mcl_params`,
  the library's :class:`~teamnav.localization.MCLParams` they stand for;
- the synchronisation's settings (§2.3's two rules, §3.2's detection trees) and each gap-fill or
  rule beyond the paper that the brain adds on top (sensor resetting on a received tree, the
  false-positive filter, §7.2's anonymous, negative and unsure detections), each documented at
  its field with what was measured;
- ``paper_rules``: the class dicts ``PAPER_RULES`` (the gap-fills whose other value is the
  paper's rule, each with the section it restores), ``PAPER_RULE_NOTES`` (the same in one line
  for the reports) and ``GAP_FILLS_KEPT`` (what the paper gives no value for), read by
  :mod:`teamnav.control.paper_rules`, and the validators that tie fields together.

What the brain does with them is in :mod:`teamnav.papers.collab_mcl.brains.localizing` (its module docstring
describes the behaviour the fields select).
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from teamnav.papers.collab_mcl.brains.delayed_integration import resolve_unsure_detections
from teamnav.control.nav.wander import WanderParams
from teamnav.control.paper_rules import paper_rules_validator
from teamnav.localization import BeamModelParams, KLDParams, LikelihoodFieldParams, MCLParams, MotionParams
from teamnav.world.grid import DEFAULT_SEES

__all__ = ["MCLWanderParams"]


class MCLWanderParams(BaseModel):
    """Parameters of ``mcl-wander-v1`` (units in the names; see :mod:`teamnav.papers.collab_mcl.brains.localizing`).

    Attributes
    ----------
    sensor : str or None
        Range sensor used for localization and for avoiding obstacles (None: the first).
    wander : WanderParams
        The wanderer (cruise speed, wall following, ...).
    max_particles, min_particles : int
        KLD-sampling bounds (global initialisation draws ``max_particles``).
    adaptive : bool
        Adaptive sample count on (else a fixed ``max_particles``).
    adapt : {"kld", "likelihood"}
        How the count adapts (:class:`~teamnav.localization.MCLParams`): KLD-sampling (Fox 2003,
        the default) or the likelihood-based adaptation of Fox et al. (1999a) that §3.1 cites (the
        paper's: "It typically uses many samples during global localization or if the position of
        the robot is lost"; a lost robot's samples fit its scans badly, so its set grows).
    adapt_ref_loglik_per_beam : float or None
        ``"likelihood"``: a tracking filter's per-beam log mean likelihood (a fill per sensor and
        map, chosen on tuning seeds; the brain logs ``loglik_per_beam``).
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
        concentrated belief (gap-fill, 349d51d). None: the weight alone, the definition
        before 349d51d, which called a lost robot's uniform belief concentrated (one connected
        cluster of weight 1 once the samples fill the free space: 2000 or more in the hallway), so
        "drop" and "delay" sent a lost robot's detections at once. Inert with
        ``send_min_cluster_weight`` 0. 1 m chosen on tuning seeds 1000-1009 of the co-travel hallway
        (sweep ``collab-mcl-cotravel-spread``, rule fixed before the runs: the lowest paired
        delay - integrate of 1, 2, 4 m): -63 ± 46 s (s.e.) at 1 m, -50 ± 47 s at 2 and 4 m, -49 ± 24 s
        with the weight alone.
    unsure_detections : {"integrate", "drop", "delay"}
        A detection made while the observer's belief is not concentrated is sent at once
        (``"integrate"``, default, §3.2), dropped, or kept and sent once it is, applied at the
        detection's time by both robots (``"delay"``, §7.2; :mod:`teamnav.papers.collab_mcl.brains.delayed_integration`,
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
        How much weight the draws get (:meth:`~teamnav.papers.collab_mcl.brains.localizing.MCLWander._inject_and_apply`).
        ``"tree"``: the set's mean weight, then eq. 14 (measured: a receiver whose belief the tree contradicts
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
        Beyond the paper (§7.2 future work): on a camera frame that does not see teammate n,
        weigh each own sample by the probability of not seeing n from it, given the points of n's
        belief that n broadcast (:mod:`teamnav.papers.collab_mcl.brains.negative_sights`, the likelihood
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
        Shipped model name or a path to a model file (:func:`~teamnav.papers.collab_mcl.brains.localizing.load_detection_model`).
    detection_period_s : float
        Camera frame period: detections are looked at once per period [s].
    min_travel_m : float
        §2.3 rule 2.
    tree_min_samples, tree_max_depth : int
        Density-tree stopping rule.
    false_positive_filter : bool
        The three gates of the :mod:`teamnav.papers.collab_mcl.brains.localizing` docstring.
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
        # §3.1: "MCL determines the sample set size on-the-fly: It typically uses many samples during
        # global localization or if the position of the robot is lost ... (see Fox et al. (1999a) for
        # details)": 1999a's likelihood-based adaptation
        "adapt": "likelihood",
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
        "adapt": "Fox §3.1 (Fox et al. 1999a): the sample count grows when the samples fit the scan badly "
                 "(likelihood-based adaptation)",
    }
    #: gap-fills the paper gives no value for: the same value in both columns (field: why)
    GAP_FILLS_KEPT: ClassVar[dict[str, str]] = {
        "min_particles": "KLD floor: §3.1 adapts the sample count on the fly (Fox et al. 1999a) and gives no "
                         "floor and no counts for its experiments",
        "max_particles": "§3.1 global localization uses many samples; no count is given",
        "random_fraction": "§3.1 'a small number of uniformly distributed, random samples'; no number",
        "min_update_m": "the paper updates on each odometry reading and scan; no rate is given",
        "min_update_deg": "as min_update_m",
        "beam": "Fig. 1's mixture; its weights and widths are not given (weights 0.7/0.1/0.1/0.1 kept from the "
                "first version; the laser's sigma_hit chosen with beam_stride by papers/collab_mcl/beam_fill.py)",
        "motion": "Fig. 2's motion model; its noise is not given",
        "tree_min_samples": "§3.2's stopping rule 'see Thrun et al. (1999b)'; no value",
        "inject_lost_prior": "inert with inject_fraction 0 (the paper's), as are inject_weighting and the "
                             "inject_heading_* settings",
        "delay_max_age_s": "inert with unsure_detections 'integrate' (the paper's)",
        "send_max_cluster_spread_m": "inert with send_min_cluster_weight 0 (the paper's)",
        "wander": "§5: the robots follow an operator or a random walk; our wanderer's settings",
        "neg_points": "inert with negative_detections false (the paper's), as are the other neg_* settings",
        "adapt_ref_loglik_per_beam": "Fox et al. 1999a's threshold on the summed likelihoods, in our units: a "
                                     "tracking filter's per-beam log mean likelihood on tuning seeds (a fill)",
        "beam_stride": "§4.1 gives 180 beams; how many the filter multiplies is not given (a fill, chosen "
                       "against a grid filter on tuning seeds: papers/collab_mcl/beam_fill.py)",
    }

    sensor: str | None = Field(None, min_length=1)
    wander: WanderParams = WanderParams(cruise_speed_mps=0.3, turn_rate_radps=0.8)
    max_particles: int = Field(5000, ge=10, le=1_000_000)
    min_particles: int = Field(300, ge=10, le=1_000_000)
    adaptive: bool = True
    adapt: Literal["kld", "likelihood"] = "kld"
    adapt_ref_loglik_per_beam: float | None = Field(None, ge=-1e6, le=1e6)
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
    send_max_cluster_spread_m: float | None = Field(1.0, gt=0.0, le=1000.0)
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
            random_fraction=self.random_fraction, adaptive=self.adaptive, adapt=self.adapt,
            likelihood_ref_per_beam=self.adapt_ref_loglik_per_beam,
            kld=KLDParams(epsilon=self.kld_epsilon, min_particles=min(self.min_particles, self.max_particles),
                          max_particles=self.max_particles),
            sonar_rays_per_cone=self.sonar_rays_per_cone, init_clearance_m=self.init_clearance_m,
            parallel=self.parallel,
        )
