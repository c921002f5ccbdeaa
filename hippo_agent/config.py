"""The hippocampal agent's configuration: one frozen, validated, documented dataclass.

Every field says its value, where the value comes from and, where the paper is ambiguous,
which reading was chosen and why. Sources (figures and measurements in ``docs/parameters.md``):

- **paper**: A. Alabi, D. Vanderelst and A. Minai, *Rapid Learning of Spatial Representations for
  Goal-Directed Navigation Based on a Novel Model of Hippocampal Place Fields* (equation numbers
  as there).
- **model-figures**: the authors' public robot controller (a Webots implementation of the model).
- **feasibility**: a prototype made before this project, which tried those figures and others.
- **tuned**: compared in this project with ``hippo_env.dmtp.run_dmtp`` on paired seeds (the same
  goals and starts for each setting); the comparisons are recorded in ``docs/parameters.md``.

All rates are per place-cell update, and the agent does one place-cell update per environment
step (about 0.15 m of travel, close to the reference's 0.14 m per update).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Literal

from hippo_env.files import unknown_fields

__all__ = ["AgentConfig"]


@dataclass(frozen=True)
class AgentConfig:
    """Parameters of :class:`hippo_agent.HippocampalAgent`.

    Construct with keyword arguments; anything left out keeps its default. A value of the wrong
    type raises ``TypeError``, an invalid value ``ValueError``, naming the field and what is allowed. ``AgentConfig.from_dict(cfg.to_dict())``
    round-trips exactly.
    """

    # ---------------------------------------------------------------- head direction cells
    n_hd: int = 8
    """Number of head-direction cells, preferred directions ``2*pi*k/n_hd`` (model-figures: 8 at
    0, 45, ..., 315 deg). Also the number of preplay directions and of ``W_pp`` slices (the paper's
    theta^h is both). Must be even and >= 4 (even: the opposite slice is then the exact negative,
    see ``cells/place.py``)."""

    # ---------------------------------------------------------------- boundary vector cells (eq. 2)
    n_bvc_directions: int = 8
    """BVC preferred allocentric directions, evenly spaced from 0 (east) counter-clockwise
    (model-figures: 8)."""
    n_bvc_distances: int = 50
    """BVC preferred distances, ``linspace(0, max distance, n)`` (model-figures: 50 over [0, max range])."""
    bvc_max_distance: float | None = None
    """Largest preferred distance in metres; ``None`` = the observation space's ``max_range``
    (model-figures: the rangefinder's max range, 10 m)."""
    bvc_sigma_r: float = 0.5
    """Radial tuning width sigma_r in metres (model-figures: 0.5 m, constant). With
    ``bvc_distance_scaled`` it is the width at distance 0."""
    bvc_distance_scaled: bool = False
    """If true, sigma_r grows with the preferred distance as in Barry et al. (2006):
    ``sigma_r(d) = bvc_sigma_r * (1 + d / bvc_beta)`` (the paper cites Barry et al. for eq. 2; the
    reference implementation kept it constant, which is our default)."""
    bvc_beta: float = 1.83
    """Barry et al.'s beta in metres (1830 mm), used only with ``bvc_distance_scaled``."""
    bvc_sigma_theta_deg: float = 1.0
    """Angular tuning width sigma_theta in degrees (model-figures: 1 to 5 deg; the narrow end is
    chosen: it keeps each BVC to a handful of rays, so the sum over rays is cheap, and with 8
    directions wider tuning adds no information)."""
    bvc_angular_cutoff: float = 3.0
    """Only rays within this many sigma_theta of a BVC's direction enter its sum (the Gaussian
    beyond 3 sigma is < 1.2 % of its peak); an implementation choice for speed."""
    bvc_peak_rate: float = 0.5
    """BVC rates are scaled so the largest possible response is this (model-figures: 0.5). The
    largest response is that of a BVC to a boundary at exactly its preferred distance across its
    whole angular tuning window (the angular Gaussian's integral, times the radial Gaussian's
    peak); one constant for all BVCs, so with ``bvc_distance_scaled`` far BVCs stay weaker, as in
    Barry et al."""
    bvc_ignore_max_range: bool = True
    """Rays that hit nothing (range >= max range) are not boundaries and do not drive BVCs. The
    paper's BVCs respond to boundaries; a ray at its maximum range has not seen one."""

    # ---------------------------------------------------------------- place cells (eqs. 3-5)
    n_place: int = 1000
    """Number of place cells N (model-figures: 200 to 1000, 1000 most often; feasibility: fewer
    leave holes between the fields)."""
    k: float = 0.5
    """Rate constant of eq. 3, ``dt / tau_p`` per update (model-figures: 0.1, later 0.5;
    feasibility: 0.1 leaves many steps with no active cell; tuned: 1.0 did worse)."""
    Gamma_pb: float = 0.3
    """Feed-forward inhibition gain Gamma^pb of eq. 3 (model-figures: 0.3)."""
    Gamma_pp: float = 0.5
    """Recurrent inhibition gain Gamma^pp of eq. 3 (model-figures: 0.5)."""
    psi: float = 1.0
    """Gain psi of eq. 4, ``v = tanh([psi s]+)`` (model-figures: 1)."""
    p_pb: float = 0.2
    """Probability that an initial BVC -> place weight ``W_pb[i, j]`` is 1 (else 0) (paper: binary
    start with probability p_pb; model-figures: 0.2 to 0.25)."""
    eta_pb: float = 0.096
    """Oja learning rate ``dt / tau_w^pb`` of eq. 5 per update (model-figures: dt = 0.096 with a
    unit time constant, about 10 updates)."""
    alpha_pb: float = math.sqrt(0.5)
    """Oja normalising factor alpha_pb of eq. 5 (model-figures: sqrt(0.5))."""
    settle_steps: int = 5
    """Eq.-3 updates run from rest on the first observation of a run, so a robot put down at
    a new start does not carry the previous place's activity; an implementation choice (the
    paper's robot is reintroduced with its network state unspecified)."""
    analysis_settle_steps: int = 30
    """Eq.-3 updates from rest used by ``place_rates_at`` / the maps (steady state for a static
    observation; 30 updates at k = 0.5 converge to within 1e-6)."""

    # ---------------------------------------------------------------- place -> place (eqs. 6-7)
    trace_rate: float = 0.3
    """Rate ``dt / tau_h`` at which the place-cell traces Upsilon^p move toward v per update (eq. 6)
    (model-figures: 0.032; feasibility: 0.032 floods replay over the whole map, about 0.2, a window
    of about one place field, gives a graded reward map). Tuned: 0.3 (a window of about 3 updates,
    0.5 m) did better than 0.2. A shorter window gives fewer long, weak links, which replay's ``tanh(v + W v)`` otherwise
    amplifies (a drive d settles near (3d)^(1/3)) into a flatter reward map."""
    hd_trace_rate: float = 1.0
    """Rate at which the head-direction trace Upsilon^h moves toward v^h (eq. 6). 1.0 = the
    instantaneous head direction, as in the reference implementation (it gated with h_k, not a
    trace); a slower trace would smear the direction across the 45-deg turns of exploration."""
    trace_floor: float = 1e-3
    """Trace values below this are set to exactly 0, so the set of cells a ``W_pp`` update touches
    stays small (a few dozen updates after a cell falls silent); an implementation choice for the
    sparse update (tuned: a higher floor, a shorter tail, did slightly worse)."""
    eta_pp: float = 1.0
    """Learning rate ``dt / tau_w^pp`` of eq. 7 (model-figures: 1, ``W[k] += h_k (...)``)."""

    # ---------------------------------------------------------------- replay (Algorithm 1)
    replay_iterations: int = 40
    """n_rs, iterations of backward replay (model-figures: 10, later 20; feasibility: 20). Each
    iteration reaches about one place-place link (1.5-2 m) further along the paths walked, so 40
    cover the geodesic span of a 15-20 m maze; the paper's model keeps 20."""
    tau_r: float = 2.0
    """Replay decay tau_r in iterations, ``exp(-t_r / tau_r)`` (model-figures: 6; feasibility: 2
    gives a map graded around the goal instead of a flat one). Replay's tanh saturates every
    reached cell, so after iteration ``t_i`` a cell gains about ``exp(-t_i / tau_r)`` per
    iteration: a short tau_r keeps the value steep around the goal, where the near misses happen;
    a long one carries value further along winding paths. Tuned with the directed dry run (open,
    maze2, maze4 and generated perfect and rooms mazes): 2.0 did better than 1.0 overall, most in
    the perfect and rooms mazes."""

    # ---------------------------------------------------------------- exploitation (eqs. 8-11)
    lambda_: float = 0.05
    """Depression lambda of eq. 11, applied to the effective reward weights of the active place
    cells at each exploitation decision, reset each run (model-figures: 0.2; feasibility: 0
    loops, 0.2 makes a self-avoiding search, 0.05 best; tuned: 0.02 and 0.1 both did worse)."""
    exploit_clearance: float = 0.6
    """While exploiting, a heading whose 30 degree cone the rangefinder shows blocked nearer than
    this (m) turns to the nearest clear one (0: off). Eq. 10's mean of two open directions at a
    corner of a corridor points at the corner's wall; each bump then costs an escape."""
    xi: float = 1e-5
    """Explore/exploit threshold xi: exploit only if the best preplayed direction's value (eq. 9)
    is >= xi (paper: max_a v^r|a >= xi; model-figures: 1e-3, which the paper's model keeps). The
    value falls about e-fold per 4 m of path, so 1e-3 cut the map off about 27 m from the goal (a
    15 m perfect maze)."""
    xi_here: float = 1e-8
    """Also explore when the value of the current place (``W_rp v / sum v``) is <= this
    (model-figures: 1e-6, which the paper's model keeps; the paper does not say; it stops the
    agent from following imagined steps out of a place the reward map has never reached)."""

    home_radius: float = 100.0
    """Within this distance (m, by path integration) of where the current goal's reward was found
    (the mean of the estimates at each reward), head there along the exploration map's walkable
    path instead of preplaying (0 = off; needs directed exploration; 100 m: from anywhere in
    any arena the generator makes). Preplay dithered round the 0.3 m goal disk (maze2) and
    drove 85 % of the steps of the well-placed runs 2-4 above 1.0 in 20 m rooms mazes
    (docs/parameters.md); where the map knows no path, preplay still steers."""
    home_arrived: float = 0.1
    """Once the estimate is this close (m) to the remembered place without a reward, the robot
    searches the ground within ``home_search_radius`` of it not yet searched in the run; when none
    is left, it anchors afresh (its estimate is most likely at a look-alike place)."""
    home_search_radius: float = 1.0
    """The radius (m) of that local search round the remembered place."""
    home_search_mark: float = 0.25
    """During the local search, ground within this distance (m) of the path counts as searched
    (the run's search marks ``search_radius``). The remembered place is where the robot entered
    the 0.3 m goal disk, at its edge; marked 0.6 m wide, a search round it passed the disk by."""
    home_bump_limit: int = 20
    """A robot that bumps into walls this many times while homing in one attempt where its map
    shows no wall (within a cell of the bump, ``ExplorationMap.wall_near``) takes its estimate to
    be at a look-alike place, as when a search finds nothing."""
    home_attempts: int = 3
    """After this many such searches without the reward in one run, the agent stops following its
    memory of the goal (home and reward map) for the rest of the run and searches the map; a
    reward found then replaces the memory (the memory was most likely written while misplaced).
    Each failed search rules out the place the estimate was at (``pi_rule_out_radius``), so the
    next attempt does not anchor in the room just searched."""

    # ---------------------------------------------------------------- exploration
    segment_min: int = 5
    """Shortest straight exploration segment in steps (model-figures: 5 place-cell updates)."""
    segment_max: int = 10
    """Longest straight exploration segment in steps, inclusive (model-figures: 10)."""
    turn_sigma_deg: float = 30.0
    """Standard deviation of the turn between segments, degrees (model-figures: N(0, 30 deg))."""
    bump_escape_steps: int = 3
    """After a bump while exploiting, this many exploration steps in the new random direction
    before preplay resumes (0 = none). The paper does not say what an exploiting robot does at a
    wall; without an escape, preplay (whose broad cosine-tuned slices also predict sliding along
    a wall) can keep choosing a blocked heading until the run times out. A bump is the same reflex
    as in exploration (model-figures: a random turn and a new segment), kept short so exploitation
    resumes quickly (tuned: 3 did better than 0, and 6 the same as 3)."""
    discrete_rounding: Literal["stochastic", "nearest"] = "stochastic"
    """How a continuous intended heading becomes one of the 8 discrete actions. ``"stochastic"``:
    the neighbouring action toward the heading is taken with probability equal to the fraction of
    the 45 deg gap, so the mean travel direction equals the intended one and exploration stays an
    isotropic random walk (not one confined to 8 lattice directions); ``"nearest"``: round to the
    closest. Used for exploration and exploitation alike (tuned: ``"nearest"`` did far worse:
    exploitation then moves on a lattice of 8 headings and overshoots)."""

    exploration: Literal["random", "directed"] = "directed"
    """How the agent explores. ``"random"``: the paper's straight segments and random turns.
    ``"directed"``: toward what its map (:mod:`hippo_agent.explore`, built from its own rangefinder
    and path integration) does not know yet: in the dry run the nearest ground not yet visited,
    in a run the nearest ground not yet searched in that run. Needs ``path_integration``; until a
    run's estimate is anchored, and after a bump, the agent explores at random."""
    map_extent: float = 45.0
    """The exploration map covers this many metres each way around the frame's origin (the dry
    run's first position): room for a 40 m arena from any start."""
    map_cell: float = 0.25
    """Side (m) of an exploration map cell; the robot (0.17 m radius) fits in one."""
    visit_radius: float = 0.7
    """Ground within this distance (m) of the robot counts as visited: the dry run's sweep runs
    lanes about this far apart."""
    search_radius: float = 0.6
    """Ground within this distance (m) counts as searched in a run, whose lanes are then about
    this far apart: twice the goal disk's radius, so a run that has searched everywhere has
    passed over the goal."""
    explore_lookahead: float = 2.0
    """Directed exploration and homing head for the farthest cell of the planned path, up to this
    far along it (m, counted as ``map_cell`` per cell), that a straight line reaches over walkable
    ground: the search's 8-connected paths zig-zag, and a point a fixed distance along them can lie
    well off the straight way."""
    transit_factor: float = 0.9
    """Directed dry run: once nothing unvisited is reachable, cross the known ground along
    shortest paths between random visited places for this many times the steps the sweep took,
    so that the place-place links (eq. 7) run along direct routes, not only along the one path of
    the sweep (feasibility: one sweep alone left replay too weak)."""
    rest_factor: float = 5.0
    """After the directed dry run, imagined transits at rest (``HippocampalAgent.rest``): this
    many imagined steps per step of the sweep, taking no environment step."""
    imagined_step: float = 0.15
    """Metres between the remembered place codes of an imagined transit: one step's travel."""
    place_cells_per_m2: float = 10.0
    """Directed dry run: place cells are recruited so that there are at least this many per
    square metre of free ground the exploration map knows (up to ``max_place_cells``): a larger
    arena gets more cells. 10 keeps the 1000 cells of a 10 m arena (96 m^2 free), where the model
    is tuned; in a 20 m arena 1000 cells would almost all be in use."""
    max_place_cells: int = 16000
    """The most place cells recruitment grows to (none is recruited beyond ``n_place`` if that is more)."""
    pi_min_anchor_steps: int = 5
    """A run's estimate is anchored no sooner than this many steps after the robot was put down
    (or found misplaced), so that the exploration map's fit (``map_beta``) accumulates over
    several scans and tells apart look-alike rooms whose difference is a door or two. Not more:
    until anchored the robot cannot home, and a misplaced anchoring is caught by the checks that
    anchor afresh (``lost_agreement``, ``home_bump_limit``, ``lost_bump_rate``)."""
    map_beta: float = 10.0
    """While a run's estimate is not anchored, each path-integration sample is weighed by
    ``exp(map_beta * agreement)``, the agreement (in [-1, 1]) of the current scan with the
    exploration map seen from there (``ExplorationMap.scan_agreement``)."""
    doubt_look_alikes: int = 8
    """On anchoring in a run, this many places at least ``pi_rule_out_radius`` away (and apart)
    where the scan fits the map best are remembered, and the scan's fit there is followed along
    with the fit at the estimate (0 = off): when a look-alike place fits better by
    ``doubt_margin`` (running means), the anchoring is taken to be wrong and the robot anchors
    afresh, away from where it was (tuned in rooms mazes; ``docs/parameters.md``)."""
    doubt_margin: float = 0.1
    """See ``doubt_look_alikes``."""
    run_map_every: int = 2
    """In runs, the map marks the searched ground and the scan's fit to the map at the estimate
    (``lost_agreement``) is checked every this many steps (the dry run maps every scan): at 0.15 m
    a step, every second scan still lands within a map cell of the last, and the fit is a running
    mean over about 10 scans."""
    map_proposals: int = 16
    """While a run's estimate is not anchored, the exploration map also proposes where the robot
    may be: this many walkable places (of every second map cell), drawn with probability
    ``exp(map_beta * agreement)`` of the current scan with the map there; ``pi_proposal_share`` of
    the redrawn samples are drawn around them. 0 = off."""
    pi_proposal_share: float = 0.5
    """Share of the redrawn samples drawn from the map's proposals (``map_proposals``)."""
    pi_lost_vote_floor: float = 0.1
    """While not anchored, the floor added to the place code's vote for each sample
    (``pi_vote_floor`` once anchored): a higher floor makes the vote weaker evidence against places
    it does not propose, which in look-alike rooms are often where the robot is."""
    pi_collapse_on_anchor: bool = True
    """On anchoring, the samples farther than twice ``pi_anchor_radius`` from the estimate are
    dropped, so that a look-alike place that the boundary code's vote favours cannot take the
    estimate over afterwards."""
    pi_rule_out_radius: float = 2.0
    """When a search round the remembered place fails (``home_attempts``), the robot is taken not
    to be where it was estimated: until it anchors again, samples within this distance (m) of
    that place, carried along by odometry, are weighed down, so the fresh anchoring does not land
    in the look-alike room just ruled out (0 = off)."""
    lost_agreement: float = 0.4
    """Once anchored, when the running mean of the scan's agreement with the map at the estimate
    falls below this, the estimate is taken to be at a look-alike place and anchored afresh."""
    lost_bump_rate: float = 0.15
    """Once anchored in a run, when the running mean of bumps per step (over about
    ``bump_rate_steps``) exceeds this, the estimate is taken to be at a look-alike place and
    anchored afresh (0 = off). Only bumps where the map shows no wall count (a wall it holds
    explains the bump). A well-placed robot bumps about 0.01 times a step; one following its map
    in the wrong room of a rooms maze, 0.3."""
    bump_rate_steps: int = 50
    """The window (steps) of that running mean."""
    learn_agreement: float = 0.6
    """In a run, the cells learn only while that running mean is at least this (-1: whenever
    anchored): an estimate at a look-alike place would teach the place code the wrong place."""
    map_in_runs: bool = False
    """In runs, the exploration map takes in walls and free ground everywhere, as in the dry run;
    if ``False``, only where it knows nothing yet: a run anchored at a look-alike place would
    otherwise write that place's walls over what the dry run mapped."""
    transit_min_distance: float = 3.0
    """A transit's destination lies at least this far (m, along the path) from where it starts."""
    sweep_patience: int = 3
    """The directed dry run's sweep counts as done after this many steps in a row with no
    unvisited ground reachable (a single step may find none while the map is being filled in)."""
    recruit_every: int = 50
    """Directed dry run: steps between checks of whether the place cells fall short of
    ``place_cells_per_m2``."""
    recruit_min: int = 250
    """Place cells recruited at least at a time, so that recruitment happens in a few large steps."""
    map_free_range: float = 4.0
    """A ray marks the exploration map's cells free up to this distance (m): farther cells are seen
    at too coarse an angle to be marked reliably."""
    map_hit_range: float = 6.0
    """A ray that ends nearer than this (m) marks a wall in the exploration map, and enters the
    scan's fit to the map."""
    map_ray_stride_deg: float = 5.0
    """One ray of the scan every this many degrees enters the exploration map."""
    map_agreement_stride_deg: float = 10.0
    """One ray of the scan every this many degrees is compared with the map (``map_beta``,
    ``lost_agreement``)."""
    map_bump_distance: float = 0.3
    """A bump marks a wall in the exploration map this far (m) ahead of the robot's centre: the
    robot's radius (0.17 m) and a little more, in the cell it bumped into."""
    map_fit_rate: float = 0.1
    """Rate per step of the running mean of the scan's fit to the map that ``lost_agreement`` is
    compared with: it spans about 10 steps."""

    # ---------------------------------------------------------------- schedule
    dry_run_steps: int = 10000
    """Goal-free steps in ``dry_run``. With ``exploration="random"``, exactly this many (paper: a
    dry run; model-figures: about 25,000 updates; feasibility: 5,000 works almost as well). With
    ``"directed"``, at most this many: the dry run ends once the sweep and its transits are done:
    medians of 5,568-6,965 steps in 20 m mazes, and 13,010-14,314 in 30 m mazes, which need this
    raised (docs/benchmarks.md, "Beyond 20 m")."""
    learn_pb_in_trials: bool = True
    """Keep the Oja rule (eq. 5) on during DMTP runs (paper: place fields develop during
    exploration; model-figures: learning stays on in runs 2-4)."""
    learn_pp_in_dry_run: bool = True
    """Let the place-place tensor learn (eq. 7) during the dry run too, not only in DMTP runs.
    The paper's dry run has only BVC -> place learning on (``AgentConfig.paper()``); learning which
    place follows which while exploring (latent learning) lets replay reach everything explored,
    along the paths actually walked, instead of only run 1's path."""
    learn_pp_in_exploitation: bool = True
    """Keep ``W_pp`` learning (eq. 7) on in exploiting runs (model-figures: learning still on)."""

    # ---------------------------------------------------------------- path integration (improved model)
    path_integration: bool = True
    """Integrate the wheel odometry into a position estimate that drives the place cells beside the
    BVCs (``hippo_agent.cells.path_integration``). Needs the environment's odometry observation
    (``gym.make("HippoMaze-v0", odometry=True)``). Not in the paper: ``AgentConfig.paper()`` turns
    it off. Why: the boundary code alone gives distant places that look alike the same cells."""
    pi_gain: float = 3.0
    """Gain of the path-integration drive of a place cell with a centre:
    ``pi_gain * (exp(-d^2 / 2 pi_sigma^2) - pi_threshold)``, ``d`` the distance from the estimate to
    the cell's centre."""
    pi_sigma: float = 0.7
    """Width (m) of the path-integration drive around a cell's centre."""
    pi_threshold: float = 0.7
    """Offset of the path-integration drive: far from its centre a cell is inhibited by
    ``pi_gain * pi_threshold``, so a look-alike place elsewhere no longer fires it."""
    pi_field_radius: float = 2.0
    """Distance (m) from its centre beyond which a place cell is silenced by
    ``pi_far_inhibition``. The Gaussian drive's far inhibition (``pi_gain * pi_threshold``) alone
    let cells whose boundary input is strong fire 4-10 m from their centres; such a cell links
    distant places in ``W_pp`` and carries the goal's value to them."""
    pi_far_inhibition: float = 10.0
    """Inhibition (same units as the drive) of a cell farther than ``pi_field_radius`` from its
    centre."""
    pi_centre_max_mass: float = 1000.0
    """Cap of the rate a centre's running mean accumulates; later firing still moves it by at
    least ``rate / pi_centre_max_mass``."""
    pi_particles: int = 200
    """Samples of the path integrator's belief."""
    pi_motion_noise: float = 0.0
    """Spread added to each sample per step, as a fraction of the distance moved."""
    pi_min_motion_noise: float = 0.001
    """Spread (m) added to each sample per step whatever the distance moved."""
    pi_vote_sigma: float = 0.4
    """Width (m) of an active cell's vote around its centre."""
    pi_anchor_radius: float = 1.0
    """Samples within this distance (m) of the heaviest one form the estimate's cluster: the
    candidate place whose share of the weight (``pi_anchor_weight``) decides anchoring. 1 m holds a
    belief as wide as the vote spreads it round one place (``pi_vote_sigma``), and look-alike rooms
    lie farther apart (wrong anchorings in the rooms tuning mazes were about 5-7 m off). At 0.3 m,
    runs whose belief held over 90 % of its weight within 1 m of the true place stayed unanchored,
    unable to home, for over 100 steps."""
    pi_anchor_weight: float = 0.8
    """Share of the weight the cluster needs before a run's estimate counts as anchored; until then
    the path-integration input and all plasticity are off."""
    pi_redraw_fraction: float = 0.2
    """While not anchored, this share of the samples is drawn afresh around the voted centres each step."""
    pi_min_mass: float = 1.0
    """A cell's centre enters the sensory vote once the cell has fired there with a summed rate of
    at least this: a centre learnt from a single weak firing is not yet a place."""
    pi_vote_floor: float = 1e-3
    """Likelihood of a sample far from every voted centre, so that no sample's weight becomes
    exactly 0 and the belief can recover from a wrong vote."""
    pi_min_mapped: float = 0.8
    """Once anchored, a vote is ignored where the cells with a centre hold less than this share of
    the boundary code's activity: at the edge of the map only the cells behind the robot have
    centres, and their vote would pull the estimate back."""
    pi_resample_ess: float = 0.5
    """The samples are resampled when their effective number falls below this share of
    ``pi_particles`` (the usual particle-filter threshold)."""
    pi_vote_by_spread: bool = True
    """Each cell learns how far from its centre the boundary code alone fires it (its spread), and
    votes for positions with a normalised Gaussian that wide: cells that also fire at distant
    look-alike places vote broadly and weakly. Why: without it a run's estimate is more often
    anchored at a look-alike place (tuned in open, maze1, maze2 and maze4; ``docs/parameters.md``)."""

    # ------------------------------------------------------------------------------------------
    @classmethod
    def paper(cls, **changes: Any) -> AgentConfig:
        """The model as the paper describes it: no path integration (the compass and the
        rangefinder only), no place-place learning in the dry run, a 5,000-step random dry run;
        no obstacle reflex while exploiting (``exploit_clearance`` 0); the rest as the defaults,
        but for ``tau_r`` 1, 20 replay iterations, ``xi`` 1e-3 and ``xi_here`` 1e-6, which its
        results in ``benchmarks/results`` were measured with (the default's were tuned for the
        directed dry run and the path-integrated code)."""
        paper = {
            "path_integration": False,
            "learn_pp_in_dry_run": False,
            "exploration": "random",
            "dry_run_steps": 5000,
            "tau_r": 1.0,
            "exploit_clearance": 0.0,
            "replay_iterations": 20,
            "xi": 1e-3,
            "xi_here": 1e-6,
        }
        return cls(**{**paper, **changes})

    def __post_init__(self) -> None:
        def bad(name: str, allowed: str) -> ValueError:
            return ValueError(f"AgentConfig.{name}={getattr(self, name)!r} is invalid; allowed: {allowed}")

        def wrong_type(name: str, allowed: str) -> TypeError:
            return TypeError(f"AgentConfig.{name}={getattr(self, name)!r} is of the wrong type; allowed: {allowed}")

        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.name == "bvc_max_distance" and value is None:
                continue
            if f.type in ("bool",):
                if not isinstance(value, bool):
                    raise wrong_type(f.name, "True or False")
            elif f.type == "int":
                if isinstance(value, bool) or not isinstance(value, int):
                    raise wrong_type(f.name, "an integer")
            elif f.type in ("float", "float | None"):
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise wrong_type(f.name, "a finite number")
                if not math.isfinite(float(value)):
                    raise bad(f.name, "a finite number (not NaN or inf)")

        def positive(*names: str) -> None:
            for n in names:
                if not getattr(self, n) > 0:
                    raise bad(n, "a value > 0")

        def non_negative(*names: str) -> None:
            for n in names:
                if not getattr(self, n) >= 0:
                    raise bad(n, "a value >= 0")

        def unit_interval(*names: str, open_low: bool = True) -> None:
            for n in names:
                v = getattr(self, n)
                if not ((0 < v <= 1) if open_low else (0 <= v <= 1)):
                    raise bad(n, "a value in (0, 1]" if open_low else "a value in [0, 1]")

        if self.n_hd < 4 or self.n_hd % 2:
            raise bad("n_hd", "an even integer >= 4")
        for n in ("n_bvc_directions", "n_bvc_distances", "n_place", "replay_iterations", "segment_min"):
            if getattr(self, n) < 1:
                raise bad(n, "an integer >= 1")
        if self.n_bvc_distances < 2:
            raise bad("n_bvc_distances", "an integer >= 2")
        non_negative("settle_steps", "dry_run_steps", "bump_escape_steps")
        if self.analysis_settle_steps < 1:
            raise bad("analysis_settle_steps", "an integer >= 1")
        if self.segment_max < self.segment_min:
            raise bad("segment_max", f"an integer >= segment_min ({self.segment_min})")
        if self.bvc_max_distance is not None:
            positive("bvc_max_distance")
        positive(
            "bvc_sigma_r", "bvc_beta", "bvc_sigma_theta_deg", "bvc_angular_cutoff", "bvc_peak_rate", "psi", "alpha_pb", "tau_r", "eta_pp"
        )
        if self.bvc_sigma_theta_deg > 45:
            raise bad("bvc_sigma_theta_deg", "a value in (0, 45] degrees")
        unit_interval("k", "trace_rate", "hd_trace_rate")
        unit_interval("p_pb", open_low=False)
        if not 0 <= self.eta_pb < 1:
            raise bad("eta_pb", "a value in [0, 1)")
        if not 0 <= self.lambda_ <= 1:
            raise bad("lambda_", "a value in [0, 1]")
        if not 0 <= self.trace_floor < 1:
            raise bad("trace_floor", "a value in [0, 1)")
        non_negative(
            "Gamma_pb", "Gamma_pp", "xi", "xi_here", "turn_sigma_deg", "pi_gain", "pi_threshold", "pi_motion_noise", "pi_min_motion_noise"
        )
        non_negative("home_radius")
        positive("home_search_radius", "home_search_mark", "home_arrived")
        if self.home_attempts < 1:
            raise bad("home_attempts", "an integer >= 1")
        non_negative("lost_bump_rate")
        if self.bump_rate_steps < 1:
            raise bad("bump_rate_steps", "an integer >= 1")
        if self.home_bump_limit < 1:
            raise bad("home_bump_limit", "an integer >= 1")
        positive("pi_sigma", "pi_field_radius", "pi_centre_max_mass", "pi_vote_sigma", "pi_anchor_radius")
        if self.pi_particles < 2:
            raise bad("pi_particles", "an integer >= 2")
        unit_interval("pi_anchor_weight", "pi_redraw_fraction")
        unit_interval("pi_proposal_share", "pi_lost_vote_floor", open_low=False)
        non_negative("map_proposals", "exploit_clearance", "pi_far_inhibition", "pi_rule_out_radius")
        if self.run_map_every < 1:
            raise bad("run_map_every", "an integer >= 1")
        if self.exploration not in ("random", "directed"):
            raise bad("exploration", "'random' or 'directed'")
        if self.exploration == "directed" and not self.path_integration:
            raise bad("exploration", "'random' when path_integration is False (directed exploration maps in the path-integration frame)")
        positive("map_extent", "map_cell", "visit_radius", "search_radius", "explore_lookahead")
        non_negative("transit_factor", "transit_min_distance", "rest_factor")
        positive("imagined_step")
        non_negative("map_beta", "doubt_look_alikes", "doubt_margin", "pi_min_anchor_steps")
        for name in ("lost_agreement", "learn_agreement"):
            if not -1 <= getattr(self, name) <= 1:
                raise bad(name, "a value in [-1, 1]")
        non_negative("place_cells_per_m2")
        for n in ("sweep_patience", "recruit_every", "recruit_min"):
            if getattr(self, n) < 1:
                raise bad(n, "an integer >= 1")
        positive("map_free_range", "map_hit_range", "map_ray_stride_deg", "map_agreement_stride_deg", "map_bump_distance")
        unit_interval("map_fit_rate", "pi_vote_floor")
        non_negative("pi_min_mass")
        unit_interval("pi_min_mapped", "pi_resample_ess", open_low=False)

        if self.discrete_rounding not in ("stochastic", "nearest"):
            raise bad("discrete_rounding", "'stochastic' or 'nearest'")

    # ------------------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """The config as a JSON-serialisable dict (field name -> value)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> AgentConfig:
        """Build a config from :meth:`to_dict` output; unknown keys raise ``ValueError``, a value of the
        wrong type ``TypeError``. Fields left out keep their defaults (a config saved before a field
        was added loads with it)."""
        if not isinstance(data, dict):
            raise TypeError(f"AgentConfig.from_dict needs a dict, got {type(data).__name__}")
        unknown = unknown_fields(cls, data)
        if unknown:
            raise ValueError(f"unknown AgentConfig field(s) {unknown}; known fields: {sorted(f.name for f in dataclasses.fields(cls))}")
        return cls(**data)

    # ------------------------------------------------------------------ the cells' parameters
    # The cell classes take every parameter as a required keyword: their values live here only.
    def bvc_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~hippo_agent.cells.BoundaryVectorCells` (besides the sensor's)."""
        return {
            "n_directions": self.n_bvc_directions,
            "n_distances": self.n_bvc_distances,
            "max_distance": self.bvc_max_distance,
            "sigma_r": self.bvc_sigma_r,
            "distance_scaled": self.bvc_distance_scaled,
            "beta": self.bvc_beta,
            "sigma_theta": math.radians(self.bvc_sigma_theta_deg),
            "angular_cutoff": self.bvc_angular_cutoff,
            "peak_rate": self.bvc_peak_rate,
            "ignore_max_range": self.bvc_ignore_max_range,
        }

    def place_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~hippo_agent.cells.PlaceCells` (besides the sizes and the generator)."""
        names = ("k", "Gamma_pb", "Gamma_pp", "psi", "p_pb", "eta_pb", "alpha_pb", "trace_rate", "hd_trace_rate", "trace_floor", "eta_pp")
        return {name: getattr(self, name) for name in names}

    def path_integrator_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~hippo_agent.cells.PathIntegrator` (besides the particle count and the generator)."""
        return {
            "motion_noise": self.pi_motion_noise,
            "min_motion_noise": self.pi_min_motion_noise,
            "vote_sigma": self.pi_vote_sigma,
            "anchor_radius": self.pi_anchor_radius,
            "anchor_weight": self.pi_anchor_weight,
            "redraw_fraction": self.pi_redraw_fraction,
            "lag": (1.0 - self.k) / self.k,  # eq. 3's Euler update lags the input by this many steps
            "min_anchor_steps": self.pi_min_anchor_steps,
            "vote_floor": self.pi_vote_floor,
            "min_mapped": self.pi_min_mapped,
            "resample_ess": self.pi_resample_ess,
            "lost_vote_floor": self.pi_lost_vote_floor,
            "proposal_share": self.pi_proposal_share,
            "collapse_on_anchor": self.pi_collapse_on_anchor,
            "rule_out_radius": self.pi_rule_out_radius,
        }

    def map_kwargs(self) -> dict[str, Any]:
        """Keyword arguments of :class:`~hippo_agent.explore.ExplorationMap`: the ``map_*`` fields
        (without the prefix), the two marking radii and the lookahead."""
        prefixed = ("extent", "cell", "free_range", "hit_range", "ray_stride_deg", "agreement_stride_deg")
        kwargs = {name: getattr(self, f"map_{name}") for name in prefixed}
        return {**kwargs, "visit_radius": self.visit_radius, "search_radius": self.search_radius, "lookahead": self.explore_lookahead}

    def replace(self, **changes: Any) -> AgentConfig:
        """A copy with some fields changed (validated like the original)."""
        return dataclasses.replace(self, **changes)
