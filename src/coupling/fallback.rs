//! The policy for an impact the LZB law cannot finish, shared by every engine.
//!
//! An impact is first solved with the paper's law (docs/model.md §2: an e = 0 contact
//! releases its energy when its compression ends and loads again from zero if
//! it is still pushed). A group that stays wedged — blocks pressed between
//! their neighbours and the ground — goes through ever smaller release and
//! reload cycles, and the impulse steps pile up. The policy, in order:
//!
//! | stage | when | what | counted as |
//! | --- | --- | --- | --- |
//! | LZB | always first | the resolver with the caller's settings | [`Resolution::Lzb`] |
//! | held | the first attempt ran out of its budget ([`FallbackPolicy::held_retry_after`]) and the group has e = 0 contacts | solved again with those contacts held closed once their compression ends (`ImpactSettings::e0_hold`, the limit of the cycles) | [`Resolution::Held`] |
//! | plastic | still unfinished, or the state became non-finite | every contact plastic with Coulomb friction ([`super::PlasticSolver`]) | [`Resolution::Plastic`] |
//!
//! A stage whose result has more kinetic energy than the group had before
//! (beyond rounding) counts as unfinished: the law never creates energy, so
//! that is a failed integration, never an answer.
//!
//! Invalid input (a NaN velocity, a zero mass) is never resolved: the error
//! is returned before any stepping and the caller keeps its velocities (the
//! engines count it as [`Resolution::Rejected`]). No other error leaves the
//! policy, so a game step never fails because of an impact.

use serde::{Deserialize, Serialize};

use crate::impact::{Body, Contact, ImpactError, ImpactOutcome, ImpactSettings, ImpactSolver};

use super::plastic::PlasticSolver;

/// Budgets of the fallback policy.
///
/// ```
/// use topple::coupling::FallbackPolicy;
/// let p = FallbackPolicy::default();
/// assert!(p.held_retry_after < p.max_steps);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FallbackPolicy {
    /// Impulse steps the first attempt may take when the group has e = 0
    /// contacts (then the held retry); a group without them gets
    /// [`FallbackPolicy::max_steps`].
    pub held_retry_after: usize,
    /// Impulse steps of any single attempt at most (then the next stage).
    pub max_steps: usize,
    /// Work of all LZB attempts of one impact together at most, in steps
    /// (accepted and rejected, and the time-domain resolver's settling of
    /// modes counted as steps: [`ImpactOutcome::settling_evaluations`] / 6)
    /// times the impact's contact points (the cost of a step grows with its
    /// contacts); an impact that would need
    /// more is finished by the next stage, at the latest the plastic solve.
    /// `None` (default): no bound beyond `max_steps` per attempt. Engines use
    /// it as a frame budget: [`super::ImpactGroups::resolve`] lets the groups
    /// of one call share it.
    #[serde(default)]
    pub max_work: Option<u64>,
    /// Under a work budget (`max_work` set; ignored without one), an impact
    /// of more free bodies than [`LargeGroup::bodies`] in which some body
    /// touches three or more others may spend at most [`LargeGroup::work`]
    /// of it on LZB attempts, and is then finished by the plastic solve: a
    /// pile ends plastic at a small cost, while an impact of a few bodies (a
    /// domino row's front and its window) or a chain of any length (a
    /// Newton's cradle, a tower stacked flat, a leaning train: each body
    /// touching at most two others) keeps the whole budget and its rebounds.
    /// `None`: every impact may spend what is left of the budget
    /// (docs/bevy.md, "Large groups end plastic"). Default
    /// [`LargeGroup::DEFAULT`].
    #[serde(default = "LargeGroup::default_some")]
    pub large_group: Option<LargeGroup>,
    /// Whether a large group's law is first probed for its progress
    /// (default `true`): the law is run until the group's fastest approach
    /// v₀ has halved, within the cap over the halvings it must make before
    /// the impact ends (log₂(v₀ / v_r), v_r the impact's rest speed); a
    /// group that does not halve it in time cannot end within its cap at
    /// that pace and ends plastic there, at a fraction of the cap's cost;
    /// one that has goes on to the law's attempts with what is left of its
    /// cap (docs/bevy.md, "Bounded frames", "The progress probe"). `false`:
    /// every large group spends its cap on the law first.
    #[serde(default = "default_true")]
    pub probe_large_groups: bool,
}

fn default_true() -> bool {
    true
}

impl Default for FallbackPolicy {
    fn default() -> Self {
        FallbackPolicy {
            held_retry_after: 20_000,
            max_steps: 200_000,
            max_work: None,
            large_group: Some(LargeGroup::DEFAULT),
            probe_large_groups: true,
        }
    }
}

/// What counts as a large impact group and how much of the work budget it
/// may spend ([`FallbackPolicy::large_group`]): more free bodies than
/// [`LargeGroup::bodies`], and a branch (a free body touching three or more
/// other free bodies), as in a pile; a chain of any length is not large.
///
/// ```
/// use topple::coupling::{FallbackPolicy, LargeGroup};
/// let p = FallbackPolicy { max_work: Some(50_000), ..FallbackPolicy::default() };
/// let big = LargeGroup::DEFAULT.bodies + 1;
/// assert_eq!(p.allowance(3, true), Some(50_000)); // a row's front: the whole budget
/// assert_eq!(p.allowance(big, true), Some(LargeGroup::DEFAULT.work)); // a pile
/// assert_eq!(p.allowance(big, false), Some(50_000)); // a long cradle: a chain
/// // without a budget (exact runs) no impact is capped
/// assert_eq!(FallbackPolicy::default().allowance(big, true), None);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct LargeGroup {
    /// Free bodies a group may have and still count as small.
    pub bodies: usize,
    /// Work (LZB steps times contact points, as [`FallbackPolicy::max_work`])
    /// a large group's LZB attempts may spend together at most.
    pub work: u64,
}

impl LargeGroup {
    /// The default: groups of more than 8 free bodies (two closing bodies
    /// and the three-contact window on each side, the largest group a
    /// single front of a domino row makes) may spend 2,000 work units,
    /// measured in docs/bevy.md ("Large groups end plastic").
    pub const DEFAULT: LargeGroup = LargeGroup {
        bodies: 8,
        work: 2_000,
    };

    fn default_some() -> Option<LargeGroup> {
        Some(Self::DEFAULT)
    }
}

impl FallbackPolicy {
    /// The work an impact of `bodies` free bodies, `branched` or a chain
    /// ([`LargeGroup`]), may spend on LZB attempts: `max_work`, capped by
    /// [`FallbackPolicy::large_group`] for a large group; `None` without a
    /// budget.
    pub fn allowance(&self, bodies: usize, branched: bool) -> Option<u64> {
        let budget = self.max_work?;
        Some(match self.large_group {
            Some(g) if self.is_large(bodies, branched) => budget.min(g.work),
            _ => budget,
        })
    }

    /// Whether an impact of `bodies` free bodies, `branched` or a chain, is
    /// a large group whose LZB attempts are capped
    /// ([`FallbackPolicy::large_group`]).
    pub fn is_large(&self, bodies: usize, branched: bool) -> bool {
        branched && self.max_work.is_some() && self.large_group.is_some_and(|g| bodies > g.bodies)
    }

    /// A large group's cap in LZB steps of an impact of `per_step` contact
    /// points (`usize::MAX` for any other impact). No margin is kept back
    /// from it as from the frame's budget: the cap shapes the cost, the
    /// frame's budget is the bound.
    fn large_cap_steps(&self, large: bool, per_step: u64) -> usize {
        match self.large_group {
            Some(g) if large => usize::try_from(g.work / per_step).unwrap_or(usize::MAX),
            _ => usize::MAX,
        }
    }
}

/// Whether some free body of an impact group touches three or more other
/// free bodies (the group's contact graph branches, as a pile's does; a
/// chain's bodies each touch at most two). `pairs` is scratch space.
fn branches(contacts: &[Contact], pairs: &mut Vec<(usize, usize)>) -> bool {
    pairs.clear();
    pairs.extend(contacts.iter().filter_map(|c| match c.bodies {
        [Some(a), Some(b)] if a != b => Some((a.min(b), a.max(b))),
        _ => None,
    }));
    if pairs.len() < 3 {
        return false;
    }
    pairs.sort_unstable();
    pairs.dedup();
    // each distinct pair counted at both of its bodies: the ends as a list
    let n = pairs.len();
    for i in 0..n {
        let (a, b) = pairs[i];
        pairs.push((a, b));
        pairs.push((b, a));
    }
    let ends = &mut pairs[n..];
    ends.sort_unstable_by_key(|e| e.0);
    ends.windows(3).any(|w| w[0].0 == w[2].0)
}

/// How an impact was resolved (see the module table).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Resolution {
    /// The LZB law finished within its budget.
    #[default]
    Lzb,
    /// Solved again with the e = 0 contacts held closed.
    Held,
    /// Resolved as a plastic impact.
    Plastic,
    /// Invalid input: not resolved, the velocities were left as they were.
    Rejected,
}

/// The LZB resolver with the fallback policy; keeps its buffers.
///
/// ```
/// use topple::coupling::{FallbackPolicy, GroupSolver, Resolution};
/// use topple::impact::{Body, Contact, ContactMaterial, ImpactOutcome, ImpactSettings};
/// let bodies = [Body::new(1.0, 0.01).with_velocity([2.0, 0.0])];
/// let wall = Contact::new([Some(0), None], [0.1, 0.0], [1.0, 0.0],
///                         ContactMaterial::hertz(1e8).with_restitution(0.5));
/// let mut out = ImpactOutcome::default();
/// let how = GroupSolver::default()
///     .solve_into(&bodies, &[wall], &ImpactSettings::adaptive(1e-6), &FallbackPolicy::default(), &mut out)
///     .unwrap();
/// assert_eq!(how, Resolution::Lzb);
/// assert!((out.bodies[0].velocity[0] + 1.0).abs() < 1e-3); // e = 0.5
/// ```
#[derive(Debug, Default)]
pub struct GroupSolver {
    lzb: ImpactSolver,
    plastic: PlasticSolver,
    /// Work of the last impact's LZB attempts (see [`FallbackPolicy::max_work`]).
    work: u64,
    /// Whether the last impact was a large group ([`FallbackPolicy::large_group`]).
    large: bool,
    /// Scratch: the body pairs of a group's contacts.
    pairs: Vec<(usize, usize)>,
}

/// [`ImpactOutcome::gains_energy`]: an LZB result that creates energy is a
/// failed integration (an adaptive step far too coarse) and goes to the
/// next stage.
pub fn gains_energy(out: &ImpactOutcome) -> bool {
    out.gains_energy()
}

/// Settling evaluations of the time-domain resolver that cost one of its
/// steps (a Dormand–Prince step evaluates six stages; the resolver's step
/// limit counts them the same way).
const SETTLING_PER_STEP: usize = 6;

/// The steps the policy keeps back from a work budget before each LZB
/// attempt of an impact of `contacts` points: an attempt stops at its step
/// limit, checked before each step and each free flight, so it may end one
/// step and two settlings of the modes (each at most 4 + 2 (points +
/// patches) evaluations, patches ≤ points) beyond it.
pub(super) fn budget_margin(contacts: usize) -> u64 {
    2 + 2 * (4 + 4 * contacts as u64) / SETTLING_PER_STEP as u64
}

/// A large group is probed only if no contact of it has a restitution above
/// this: each load cycle of such a contact gives back at most half the
/// approach it stopped, so the group's fastest approach falls by halves as
/// its bounces go on. A more elastic group can hand its approach on
/// undiminished (a cluster of elastic balls: a Newton's cradle with
/// branches), so that the approach falls only at the impact's end and
/// the pace of its first halving says nothing.
const PROBE_MAX_RESTITUTION: f64 = 0.5;

/// A large group is probed only if the law must halve its fastest approach
/// at least this many times before the impact ends (see
/// [`GroupSolver::probe_limit`]).
const PROBE_MIN_HALVINGS: f64 = 2.0;

/// The fastest approach speed −n·(v₂ − v₁) at any contact point of an
/// impact before it (m/s, ≥ 0; the world and fixed bodies move with the
/// velocity they are given).
fn fastest_approach(bodies: &[Body], contacts: &[Contact]) -> f64 {
    let world = bodies.len();
    let at = |slot: usize, arm: [f64; 2]| {
        if slot == world {
            return [0.0, 0.0];
        }
        let b = &bodies[slot];
        [
            b.velocity[0] - b.angular_velocity * arm[1],
            b.velocity[1] + b.angular_velocity * arm[0],
        ]
    };
    contacts
        .iter()
        .map(|c| {
            let f = c.frame(bodies);
            let (va, vb) = (at(f.a, f.arm_a), at(f.b, f.arm_b));
            -(f.normal[0] * (vb[0] - va[0]) + f.normal[1] * (vb[1] - va[1]))
        })
        .fold(0.0, f64::max)
}

fn unfinished(r: &Result<(), ImpactError>) -> bool {
    matches!(
        r,
        Err(ImpactError::StepLimit { .. } | ImpactError::NonFinite { .. })
    )
}

impl GroupSolver {
    /// Resolves one impact group into `out` by the policy. Errors only for
    /// invalid input, before any stepping.
    pub fn solve_into(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
        policy: &FallbackPolicy,
        out: &mut ImpactOutcome,
    ) -> Result<Resolution, ImpactError> {
        let how = self.by_policy(bodies, contacts, settings, policy, out);
        if how.is_ok() {
            crate::impact::audit::record(bodies, contacts, out);
        }
        how
    }

    /// Work of the LZB attempts of the last [`GroupSolver::solve_into`]: steps
    /// (accepted and rejected, and settling evaluations / 6) times contact
    /// points ([`FallbackPolicy::max_work`]).
    pub fn last_work(&self) -> u64 {
        self.work
    }

    /// Whether the last [`GroupSolver::solve_into`] was a large group, its
    /// LZB attempts capped ([`FallbackPolicy::large_group`]).
    pub fn last_was_large(&self) -> bool {
        self.large
    }

    fn by_policy(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
        policy: &FallbackPolicy,
        out: &mut ImpactOutcome,
    ) -> Result<Resolution, ImpactError> {
        self.work = 0;
        self.large = false;
        let per_step = contacts.len().max(1) as u64;
        // steps left to all attempts together under `max_work`
        let left = policy.max_work.map_or(usize::MAX, |w| {
            usize::try_from(w / per_step).unwrap_or(usize::MAX)
        });
        let can_hold = !settings.e0_hold && contacts.iter().any(|c| c.material.restitution == 0.0);
        let budget = if can_hold {
            policy.held_retry_after.min(policy.max_steps)
        } else {
            policy.max_steps
        };
        // what an attempt may take past its step limit is kept back
        let margin = if policy.max_work.is_some() {
            usize::try_from(budget_margin(contacts.len())).unwrap_or(usize::MAX)
        } else {
            0
        };
        let mut left = left.saturating_sub(margin);
        self.large = policy.is_large(bodies.len(), branches(contacts, &mut self.pairs));
        let mut cap = policy.large_cap_steps(self.large, per_step);
        if let Some(probe) = self.probe_settings(bodies, contacts, settings, policy, cap) {
            // a group whose law does not halve its fastest approach within
            // its share of the cap cannot end within the cap at that pace
            if left > 0 && !self.probe(bodies, contacts, &probe, &mut left, &mut cap, out)? {
                cap = 0;
            }
            left = left.saturating_sub(margin);
        }
        if left > 0 && cap > 0 {
            let first = ImpactSettings {
                max_steps: budget.min(settings.max_steps).min(left).min(cap).max(1),
                ..*settings
            };
            Self::fresh(out);
            let result = self.lzb.solve_into(bodies, contacts, &first, out);
            self.charge(out, per_step, &mut left, &mut cap);
            if !unfinished(&result) && !gains_energy(out) {
                return result.map(|()| Resolution::Lzb);
            }
        }
        left = left.saturating_sub(margin);
        if can_hold && left > 0 && cap > 0 {
            let held = ImpactSettings {
                e0_hold: true,
                max_steps: policy
                    .max_steps
                    .min(settings.max_steps)
                    .min(left)
                    .min(cap)
                    .max(1),
                ..*settings
            };
            Self::fresh(out);
            let result = self.lzb.solve_into(bodies, contacts, &held, out);
            self.charge(out, per_step, &mut left, &mut cap);
            if !unfinished(&result) && !gains_energy(out) {
                return result.map(|()| Resolution::Held);
            }
        }
        self.plastic.set_rest_speed(settings.rest_speed);
        self.plastic.solve_into(bodies, contacts, out);
        Ok(Resolution::Plastic)
    }

    /// A large group's progress probe ([`FallbackPolicy::probe_large_groups`]):
    /// the law on the group until its fastest approach v₀ has halved (the
    /// impact ended at the rest speed v₀/2: no point approaching faster,
    /// none storing the energy to rebound faster), within the cap over the
    /// halvings the law must make before the impact ends at its rest speed
    /// v_r, log₂(v₀ / v_r). `None` (no probe: the cap alone) when the group
    /// is not large, the impact has no rest speed to end at, or v₀ < 4 v_r
    /// (fewer than two halvings: the probe would be the impact).
    fn probe_settings(
        &self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
        policy: &FallbackPolicy,
        cap: usize,
    ) -> Option<ImpactSettings> {
        let rest = settings.rest_speed;
        let elastic = contacts
            .iter()
            .any(|c| c.material.restitution > PROBE_MAX_RESTITUTION);
        let no_rest = rest.is_nan() || rest <= 0.0;
        if !policy.probe_large_groups || !self.large || cap == 0 || no_rest || elastic {
            return None;
        }
        let v0 = fastest_approach(bodies, contacts);
        let halvings = (v0 / rest).log2();
        (halvings >= PROBE_MIN_HALVINGS).then(|| ImpactSettings {
            rest_speed: 0.5 * v0,
            max_steps: ((cap as f64 / halvings) as usize)
                .min(settings.max_steps)
                .max(1),
            ..*settings
        })
    }

    /// Runs the progress probe `probe` within what is `left` of the budget
    /// and charges its steps to the budget and to the large group's `cap`
    /// (the group's LZB attempts, the probe among them, spend at most its
    /// cap). Whether the fastest approach halved in time; errors only for
    /// invalid input.
    fn probe(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        probe: &ImpactSettings,
        left: &mut usize,
        cap: &mut usize,
        out: &mut ImpactOutcome,
    ) -> Result<bool, ImpactError> {
        let within = ImpactSettings {
            max_steps: probe.max_steps.min(*left).max(1),
            ..*probe
        };
        Self::fresh(out);
        let result = self.lzb.solve_into(bodies, contacts, &within, out);
        self.charge(out, contacts.len().max(1) as u64, left, cap);
        match result {
            Ok(()) => Ok(true),
            Err(ImpactError::StepLimit { .. } | ImpactError::NonFinite { .. }) => Ok(false),
            Err(e) => Err(e),
        }
    }

    /// Adds an attempt's steps to the work and takes them from `left` and
    /// from the large group's `cap`.
    fn charge(
        &mut self,
        out: &mut ImpactOutcome,
        per_step: u64,
        left: &mut usize,
        cap: &mut usize,
    ) {
        let steps = out.steps + out.rejected_steps + out.settling_evaluations / SETTLING_PER_STEP;
        self.work += steps as u64 * per_step;
        *left = left.saturating_sub(steps);
        *cap = cap.saturating_sub(steps);
    }

    /// Clears the step counts an attempt that fails its input check leaves
    /// as they were.
    fn fresh(out: &mut ImpactOutcome) {
        out.steps = 0;
        out.rejected_steps = 0;
        out.settling_evaluations = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::impact::ContactMaterial;

    fn wedge() -> (Vec<Body>, Vec<Contact>) {
        // a ball driven into a corner between two walls with e = 0
        let bodies = vec![Body::new(1.0, 0.004).with_velocity([1.0, -1.0])];
        let m = ContactMaterial::hertz(1e8).with_restitution(0.0);
        let contacts = vec![
            Contact::new([Some(0), None], [0.1, 0.0], [1.0, 0.0], m),
            Contact::new([None, Some(0)], [0.0, -0.1], [0.0, 1.0], m),
        ];
        (bodies, contacts)
    }

    #[test]
    fn a_tiny_budget_ends_held_or_plastic_and_never_creates_energy() {
        let (bodies, contacts) = wedge();
        let mut out = ImpactOutcome::default();
        let mut solver = GroupSolver::default();
        let tight = FallbackPolicy {
            held_retry_after: 3,
            max_steps: 4,
            ..FallbackPolicy::default()
        };
        let how = solver
            .solve_into(
                &bodies,
                &contacts,
                &ImpactSettings::fixed(1e-4),
                &tight,
                &mut out,
            )
            .unwrap();
        assert!(matches!(how, Resolution::Held | Resolution::Plastic));
        assert!(out.kinetic_energy_after <= out.kinetic_energy_before);
        // the corner stops the ball (both walls are e = 0): at rest
        let v = out.bodies[0].velocity;
        assert!(v[0].abs() < 1e-6 && v[1].abs() < 1e-6, "{v:?}");
    }

    #[test]
    fn a_work_budget_bounds_the_attempts_and_ends_plastic() {
        let (bodies, contacts) = wedge();
        let mut out = ImpactOutcome::default();
        let mut solver = GroupSolver::default();
        // two contacts: a work of 10 allows 5 steps over all attempts
        let policy = FallbackPolicy {
            max_work: Some(10),
            ..FallbackPolicy::default()
        };
        let how = solver
            .solve_into(
                &bodies,
                &contacts,
                &ImpactSettings::fixed(1e-4),
                &policy,
                &mut out,
            )
            .unwrap();
        assert_eq!(how, Resolution::Plastic);
        assert!(solver.last_work() <= 10, "{}", solver.last_work());
        assert!(out.kinetic_energy_after <= out.kinetic_energy_before);
        // no work left: plastic at once, no LZB step taken
        let none = FallbackPolicy {
            max_work: Some(1),
            ..FallbackPolicy::default()
        };
        let how = solver
            .solve_into(
                &bodies,
                &contacts,
                &ImpactSettings::fixed(1e-4),
                &none,
                &mut out,
            )
            .unwrap();
        assert_eq!((how, solver.last_work()), (Resolution::Plastic, 0));
        // without a bound the same impact finishes by the law
        let how = solver
            .solve_into(
                &bodies,
                &contacts,
                &ImpactSettings::adaptive(1e-4),
                &FallbackPolicy::default(),
                &mut out,
            )
            .unwrap();
        assert_ne!(how, Resolution::Plastic);
        assert!(solver.last_work() > 0);
    }

    /// An impact of the 150-box pile (17 boxes, 47 contact points, captured
    /// from the Bevy frame bench) whose modes cycle at its switches (each
    /// settling ran to its cap before settlings ended at a repeated state,
    /// tests/impact/rest.rs).
    fn cycling() -> crate::impact::capture::CapturedImpact {
        serde_json::from_str(include_str!("../../tests/data/settling-cycle.json"))
            .expect("the captured impact")
    }

    #[test]
    fn settling_is_counted_as_work_and_bounded_by_the_budget() {
        let cap = cycling();
        let per_step = cap.contacts.len() as u64;
        let mut out = ImpactOutcome::default();
        let mut solver = GroupSolver::default();
        // the resolver alone, with its own step limit, settles its modes
        // at every switch
        let _ = ImpactSolver::new().solve_into(&cap.bodies, &cap.contacts, &cap.settings, &mut out);
        let settling = out.settling_evaluations;
        assert!(settling > 0, "{out:?}");
        // with the fallback policy and no bound, the work charged includes
        // the settling of the first attempt (the same solve)
        solver
            .solve_into(
                &cap.bodies,
                &cap.contacts,
                &cap.settings,
                &FallbackPolicy::default(),
                &mut out,
            )
            .unwrap();
        let unbounded = solver.last_work();
        assert!(
            unbounded >= (settling / SETTLING_PER_STEP) as u64 * per_step,
            "{unbounded} {settling}"
        );
        assert!(!gains_energy(&out));
        // a budget a tenth of that: the attempts stop at it, overshooting
        // by at most the last settling before the check (its cap is
        // 4 + 2 (points + patches) evaluations; patches ≤ points), then the
        // plastic solve finishes the impact without creating energy
        let budget = unbounded / 10;
        let how = solver
            .solve_into(
                &cap.bodies,
                &cap.contacts,
                &cap.settings,
                &FallbackPolicy {
                    max_work: Some(budget),
                    ..FallbackPolicy::default()
                },
                &mut out,
            )
            .unwrap();
        let settle_cap = (4 + 4 * per_step) / SETTLING_PER_STEP as u64 + 1;
        assert_eq!(how, Resolution::Plastic);
        assert!(
            solver.last_work() <= budget + 2 * settle_cap * per_step,
            "{} {budget}",
            solver.last_work()
        );
        assert!(out.kinetic_energy_after <= out.kinetic_energy_before);
    }

    /// The fastest approach left at any contact after `out` (m/s, ≥ 0):
    /// n·(v₂ − v₁) at the contact point from the outcome's velocities.
    fn approach_left(bodies: &[Body], contacts: &[Contact], out: &ImpactOutcome) -> f64 {
        let at = |i: Option<usize>, p: [f64; 2]| match i {
            Some(i) => {
                let (b, v) = (&bodies[i], &out.bodies[i]);
                let r = [p[0] - b.position[0], p[1] - b.position[1]];
                [
                    v.velocity[0] - v.angular_velocity * r[1],
                    v.velocity[1] + v.angular_velocity * r[0],
                ]
            }
            None => [0.0, 0.0],
        };
        contacts
            .iter()
            .map(|c| {
                let (v1, v2) = (at(c.bodies[0], c.point), at(c.bodies[1], c.point));
                -(c.normal[0] * (v2[0] - v1[0]) + c.normal[1] * (v2[1] - v1[1]))
            })
            .fold(0.0, f64::max)
    }

    /// Total linear momentum of the bodies (kg·m/s), before or after.
    fn momentum(bodies: &[Body], after: Option<&ImpactOutcome>) -> [f64; 2] {
        let mut p = [0.0; 2];
        for (i, b) in bodies.iter().enumerate() {
            let v = after.map_or(b.velocity, |o| o.bodies[i].velocity);
            p[0] += b.mass * v[0];
            p[1] += b.mass * v[1];
        }
        p
    }

    /// `n` equal balls (1 kg, r = 0.05 m) touching in a line along x, the
    /// first at 1 m/s: a Newton's cradle with restitution `e`, no walls.
    fn cradle(n: usize, e: f64) -> (Vec<Body>, Vec<Contact>) {
        let bodies: Vec<Body> = (0..n)
            .map(|i| {
                let b = Body::new(1.0, 0.001).with_position([0.1 * i as f64, 0.0]);
                if i == 0 {
                    b.with_velocity([1.0, 0.0])
                } else {
                    b
                }
            })
            .collect();
        let m = ContactMaterial::hertz(1e8).with_restitution(e);
        let contacts = (1..n)
            .map(|i| {
                Contact::new(
                    [Some(i - 1), Some(i)],
                    [0.1 * i as f64 - 0.05, 0.0],
                    [1.0, 0.0],
                    m,
                )
            })
            .collect();
        (bodies, contacts)
    }

    /// Under a frame budget, the default policy's large groups.
    fn budgeted() -> FallbackPolicy {
        FallbackPolicy {
            max_work: Some(crate::coupling::ToppleSettings::DEFAULT_STEP_WORK),
            ..FallbackPolicy::default()
        }
    }

    /// 15 boxes and 33 contact points of the pile landing on one another
    /// (captured from the pile scene; tests/impact/rest.rs), small enough
    /// for the plastic solve's direct stage.
    fn landing() -> (Vec<Body>, Vec<Contact>) {
        let input: serde_json::Value = serde_json::from_str(include_str!(
            "../../tests/data/pile-landing-33-contacts.json"
        ))
        .expect("the captured impact");
        let bodies = serde_json::from_value(input["bodies"].clone()).expect("bodies");
        let contacts = serde_json::from_value(input["contacts"].clone()).expect("contacts");
        (bodies, contacts)
    }

    #[test]
    fn a_large_group_ends_plastic_within_its_cap_without_approach_or_energy_gain() {
        let (bodies, contacts) = landing();
        // ended at a hundredth of the fastest body's speed, as the engines
        // end an impact at their rest fraction
        let fastest = bodies
            .iter()
            .map(|b| b.velocity[0].hypot(b.velocity[1]))
            .fold(0.0, f64::max);
        let settings = ImpactSettings {
            rest_speed: 1e-2 * fastest,
            ..ImpactSettings::adaptive(1e-6)
        };
        let per_step = contacts.len() as u64;
        let large = LargeGroup::DEFAULT;
        assert!(bodies.len() > large.bodies);
        let mut out = ImpactOutcome::default();
        let mut solver = GroupSolver::default();
        // with the frame budget alone it spends most of the budget before
        // the plastic solve (its law needs about twice the budget)
        let uncapped = FallbackPolicy {
            large_group: None,
            ..budgeted()
        };
        solver
            .solve_into(&bodies, &contacts, &settings, &uncapped, &mut out)
            .unwrap();
        assert!(
            solver.last_work() > 10 * large.work,
            "{}",
            solver.last_work()
        );
        let how = solver
            .solve_into(&bodies, &contacts, &settings, &budgeted(), &mut out)
            .unwrap();
        assert_eq!(how, Resolution::Plastic);
        // the cap, overshot by at most the last step and two settlings of
        // the modes before the check (4 + 2 (points + patches) evaluations
        // each, patches ≤ points)
        let settle = (4 + 4 * per_step) / SETTLING_PER_STEP as u64 + 1;
        assert!(
            solver.last_work() <= large.work + (1 + 2 * settle) * per_step,
            "{}",
            solver.last_work()
        );
        // the plastic outcome: no contact approaching faster than the rest
        // speed the impact ends at (the LZB resolver's end, passed to the
        // plastic solve), no energy created
        let rest = ImpactOutcome {
            bodies: bodies
                .iter()
                .map(|b| crate::impact::BodyVelocity {
                    velocity: b.velocity,
                    angular_velocity: b.angular_velocity,
                })
                .collect(),
            ..ImpactOutcome::default()
        };
        let speed = approach_left(&bodies, &contacts, &rest);
        assert!(speed > 0.0);
        let left = approach_left(&bodies, &contacts, &out);
        assert!(left <= settings.rest_speed, "{left} of {speed}");
        // without a rest speed the plastic solve finishes it exactly: no
        // contact approaching faster than 10⁻⁸ of the impact speed (the
        // plastic solve's own tests ask the same of random stacks)
        let mut exact = ImpactOutcome::default();
        PlasticSolver::default().solve_into(&bodies, &contacts, &mut exact);
        let exact_left = approach_left(&bodies, &contacts, &exact);
        assert!(exact_left <= 1e-8 * speed, "{exact_left} of {speed}");
        assert!(!exact.gains_energy());
        let ke0: f64 = bodies.iter().map(Body::kinetic_energy).sum();
        let ke1: f64 = bodies
            .iter()
            .zip(&out.bodies)
            .map(|(b, v)| {
                0.5 * b.mass * (v.velocity[0].powi(2) + v.velocity[1].powi(2))
                    + 0.5 * b.inertia * v.angular_velocity.powi(2)
            })
            .sum();
        assert!(ke1 <= ke0 * (1.0 + 1e-12), "{ke1} > {ke0}");
    }

    #[test]
    fn a_pile_branches_and_a_chain_does_not() {
        let mut pairs = Vec::new();
        let (_, chain) = cradle(20, 1.0);
        assert!(!branches(&chain, &mut pairs));
        // the captured pile landing: some box touches three or more others
        let (_, pile) = landing();
        assert!(branches(&pile, &mut pairs));
        // a star of three bodies around one, each pair touching at two
        // points (λ points), and ground contacts: branched
        let m = ContactMaterial::hertz(1e8);
        let at = |a, b| Contact::new([Some(a), b], [0.0, 0.0], [1.0, 0.0], m);
        let star: Vec<Contact> = [1, 2, 3]
            .iter()
            .flat_map(|&k| [at(0, Some(k)), at(0, Some(k)), at(k, None)])
            .collect();
        assert!(branches(&star, &mut pairs));
        // two of them: a chain again, however many points a pair has
        assert!(!branches(&star[..6], &mut pairs));
    }

    /// A Newton's cradle of many balls is a chain, not a large group: under
    /// the default budget it ends by the law however long it is (the
    /// 12-ball cradle with e = 0.9 needs 3,300 work units, past the large
    /// groups' cap), with momentum kept and the energy of e < 1.
    #[test]
    fn a_long_cradle_keeps_the_law_under_the_budget() {
        let settings = ImpactSettings::adaptive(1e-6);
        let mut solver = GroupSolver::default();
        let mut out = ImpactOutcome::default();
        for n in [12, 20] {
            let (bodies, contacts) = cradle(n, 0.9);
            let how = solver
                .solve_into(&bodies, &contacts, &settings, &budgeted(), &mut out)
                .unwrap();
            assert_eq!(how, Resolution::Lzb, "{n} balls");
            assert!(!solver.last_was_large());
            assert!(solver.last_work() > LargeGroup::DEFAULT.work, "{n} balls");
            let (p0, p1) = (momentum(&bodies, None), momentum(&bodies, Some(&out)));
            assert!((p1[0] - p0[0]).abs() < 1e-12, "{p1:?}");
            // some energy lost (e < 1), none created; a plastic cradle
            // would keep only 1/n of it
            let ke0: f64 = bodies.iter().map(Body::kinetic_energy).sum();
            assert!(out.kinetic_energy_after < ke0);
            assert!(out.kinetic_energy_after > 2.0 / n as f64 * ke0, "{n} balls");
        }
    }

    #[test]
    fn small_groups_and_chains_keep_the_law() {
        let settings = ImpactSettings::adaptive(1e-6);
        let mut solver = GroupSolver::default();
        let (mut a, mut b) = (ImpactOutcome::default(), ImpactOutcome::default());
        for n in [4, LargeGroup::DEFAULT.bodies + 4] {
            let (bodies, contacts) = cradle(n, 1.0);
            let how = solver
                .solve_into(&bodies, &contacts, &settings, &budgeted(), &mut a)
                .unwrap();
            let uncapped = FallbackPolicy {
                large_group: None,
                ..budgeted()
            };
            solver
                .solve_into(&bodies, &contacts, &settings, &uncapped, &mut b)
                .unwrap();
            // the law, the same bits as without the cap
            assert_eq!(how, Resolution::Lzb, "{n} balls");
            assert_eq!(a.bodies, b.bodies, "{n} balls");
            // an elastic cradle: momentum kept, energy kept to the
            // tolerance, the last ball leaves with the first one's speed
            let (p0, p1) = (momentum(&bodies, None), momentum(&bodies, Some(&a)));
            assert!(
                (p1[0] - p0[0]).abs() < 1e-12 && p1[1].abs() < 1e-12,
                "{p1:?}"
            );
            let ke0: f64 = bodies.iter().map(Body::kinetic_energy).sum();
            assert!(
                (a.kinetic_energy_after - ke0).abs() < 1e-5 * ke0,
                "{n} balls"
            );
        }
    }

    /// A star of `1 + 4·len` equal balls (1 kg, r = 0.05 m, no walls): a
    /// centre ball and four arms of `len` touching balls along ±x and ±y,
    /// the far ball of the −x arm driven at 1 m/s into the rest, restitution
    /// `e` everywhere. The centre touches four balls: a branched group, and
    /// with two or more balls an arm a large one.
    fn star(len: usize, e: f64) -> (Vec<Body>, Vec<Contact>) {
        let m = ContactMaterial::hertz(1e8).with_restitution(e);
        let mut bodies = vec![Body::new(1.0, 0.001)];
        let mut contacts = Vec::new();
        for d in [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]] {
            let mut previous = 0;
            for k in 1..=len {
                let at = [0.1 * k as f64 * d[0], 0.1 * k as f64 * d[1]];
                let mut ball = Body::new(1.0, 0.001).with_position(at);
                if d[0] < 0.0 && k == len {
                    ball = ball.with_velocity([1.0, 0.0]);
                }
                bodies.push(ball);
                let i = bodies.len() - 1;
                let point = [at[0] - 0.05 * d[0], at[1] - 0.05 * d[1]];
                contacts.push(Contact::new([Some(previous), Some(i)], point, d, m));
                previous = i;
            }
        }
        (bodies, contacts)
    }

    /// The settings of an engine's impact: ended at a hundredth of the
    /// fastest approach (1 m/s in the stars), as the engines end an impact
    /// at their rest fraction.
    /// Solves one large group under [`budgeted`] at [`at_rest_fraction`]
    /// with the progress probe (into `probed`) and with the cap alone (into
    /// `capped`): (resolution, LZB work) of each.
    fn probe_and_cap_alone(
        solver: &mut GroupSolver,
        bodies: &[Body],
        contacts: &[Contact],
        probed: &mut ImpactOutcome,
        capped: &mut ImpactOutcome,
    ) -> ((Resolution, u64), (Resolution, u64)) {
        let settings = at_rest_fraction();
        let how = solver
            .solve_into(bodies, contacts, &settings, &budgeted(), probed)
            .unwrap();
        assert!(solver.last_was_large());
        let with_probe = solver.last_work();
        let whole_cap = FallbackPolicy {
            probe_large_groups: false,
            ..budgeted()
        };
        let without = solver
            .solve_into(bodies, contacts, &settings, &whole_cap, capped)
            .unwrap();
        ((how, with_probe), (without, solver.last_work()))
    }

    fn at_rest_fraction() -> ImpactSettings {
        ImpactSettings {
            rest_speed: 1e-2,
            ..ImpactSettings::adaptive(1e-6)
        }
    }

    /// The captured pile landing (15 boxes, 33 points, e = 0.3) does not
    /// halve its fastest approach within its share of the cap: the probe
    /// ends it plastic after that share, a fraction of the cap, with the
    /// same velocities as the plastic solve after the whole cap.
    #[test]
    fn a_pile_landing_that_cannot_end_within_its_cap_ends_plastic_at_its_probe() {
        let (bodies, contacts) = landing();
        let fastest = fastest_approach(&bodies, &contacts);
        let settings = ImpactSettings {
            rest_speed: 1e-2 * fastest,
            ..ImpactSettings::adaptive(1e-6)
        };
        let per_step = contacts.len() as u64;
        let cap = LargeGroup::DEFAULT.work / per_step;
        let mut solver = GroupSolver::default();
        let (mut probed, mut capped) = (ImpactOutcome::default(), ImpactOutcome::default());
        let how = solver
            .solve_into(&bodies, &contacts, &settings, &budgeted(), &mut probed)
            .unwrap();
        assert_eq!(how, Resolution::Plastic);
        assert!(solver.last_was_large());
        let work = solver.last_work();
        // the probe's limit: the cap over log₂(v₀/v_r) = log₂ 100 halvings,
        // overshot by at most the last step and two settlings
        let limit = (cap as f64 / 100f64.log2()) as u64;
        let settle = (4 + 4 * per_step) / SETTLING_PER_STEP as u64 + 1;
        assert!(work <= (limit + 1 + 2 * settle) * per_step, "{work}");
        assert!(work < LargeGroup::DEFAULT.work / 2, "{work}");
        // without the probe: the whole cap, then the same plastic solve
        let whole_cap = FallbackPolicy {
            probe_large_groups: false,
            ..budgeted()
        };
        let how = solver
            .solve_into(&bodies, &contacts, &settings, &whole_cap, &mut capped)
            .unwrap();
        assert_eq!(how, Resolution::Plastic);
        assert!(
            solver.last_work() > 3 * work,
            "{} {work}",
            solver.last_work()
        );
        assert_eq!(probed.bodies, capped.bodies);
        // the plastic outcome on its own: no contact approaching faster
        // than the rest speed, no energy created, every impulse in its
        // friction cone (|P_t| ≤ μ_s P_n, P_n ≥ 0)
        let left = approach_left(&bodies, &contacts, &probed);
        assert!(left <= settings.rest_speed, "{left}");
        assert!(!probed.gains_energy());
        for (c, p) in contacts.iter().zip(&probed.contacts) {
            let mu = c.material.stick_friction.max(c.material.friction);
            assert!(p.normal_impulse >= 0.0, "{p:?}");
            assert!(
                p.tangent_impulse.abs() <= mu * p.normal_impulse * (1.0 + 1e-12),
                "{p:?}"
            );
        }
    }

    /// Large groups whose law ends within the cap and whose contacts give
    /// back at most half their approach (e ≤ ½) pass the probe and end by
    /// the law, with the bits of the cap alone; momentum is kept (no walls)
    /// and no energy created.
    #[test]
    fn a_branched_group_that_ends_within_its_cap_passes_the_probe() {
        let mut solver = GroupSolver::default();
        let (mut probed, mut capped) = (ImpactOutcome::default(), ImpactOutcome::default());
        for (len, e) in [(2, 0.0), (2, 0.3), (2, 0.5), (3, 0.0), (3, 0.5)] {
            let (bodies, contacts) = star(len, e);
            let ((how, with_probe), (without, cap_alone)) =
                probe_and_cap_alone(&mut solver, &bodies, &contacts, &mut probed, &mut capped);
            assert_eq!(
                (how, without),
                (Resolution::Lzb, Resolution::Lzb),
                "{len} {e}"
            );
            assert_eq!(probed.bodies, capped.bodies, "{len} {e}");
            // the probe's work comes on top of the law's
            assert!(with_probe > cap_alone, "{len} {e}");
            let (p0, p1) = (momentum(&bodies, None), momentum(&bodies, Some(&probed)));
            assert!(
                (p1[0] - p0[0]).abs() < 1e-12 && p1[1].abs() < 1e-12,
                "{len} {e} {p1:?}"
            );
            assert!(!probed.gains_energy(), "{len} {e}");
        }
    }

    /// A large group that passes the probe but whose law needs more than
    /// its cap (a 13-ball star with e = 0.3, 3,420 units unbounded) spends
    /// at most the cap on the probe and the attempt together, then ends
    /// plastic, creating no energy.
    #[test]
    fn the_probe_is_paid_from_the_cap() {
        let (bodies, contacts) = star(3, 0.3);
        let mut solver = GroupSolver::default();
        let mut out = ImpactOutcome::default();
        let unbounded = FallbackPolicy {
            large_group: None,
            ..budgeted()
        };
        let how = solver
            .solve_into(
                &bodies,
                &contacts,
                &at_rest_fraction(),
                &unbounded,
                &mut out,
            )
            .unwrap();
        assert_eq!(how, Resolution::Lzb);
        let cap = LargeGroup::DEFAULT.work;
        assert!(solver.last_work() > cap, "{}", solver.last_work());
        let how = solver
            .solve_into(
                &bodies,
                &contacts,
                &at_rest_fraction(),
                &budgeted(),
                &mut out,
            )
            .unwrap();
        assert_eq!(how, Resolution::Plastic);
        // the attempt after the probe: the cap less the probe's steps,
        // overshot by at most its last step and two settlings
        let per_step = contacts.len() as u64;
        let settle = (4 + 4 * per_step) / SETTLING_PER_STEP as u64 + 1;
        assert!(
            solver.last_work() <= cap + (1 + 2 * settle) * per_step,
            "{}",
            solver.last_work()
        );
        assert!(!out.gains_energy());
    }

    /// An elastic star hands the striking ball's approach on undiminished
    /// (a Newton's cradle with branches): its fastest approach falls only
    /// at the impact's end, so it is not probed; it ends by the law with
    /// the bits and the work of the cap alone, energy and momentum kept.
    #[test]
    fn an_elastic_large_group_is_not_probed() {
        let mut solver = GroupSolver::default();
        let (mut probed, mut capped) = (ImpactOutcome::default(), ImpactOutcome::default());
        for len in [2, 3] {
            let (bodies, contacts) = star(len, 1.0);
            let ((how, work), (_, cap_alone)) =
                probe_and_cap_alone(&mut solver, &bodies, &contacts, &mut probed, &mut capped);
            assert_eq!(how, Resolution::Lzb, "{len}");
            assert_eq!(
                (probed.bodies.clone(), work),
                (capped.bodies.clone(), cap_alone)
            );
            // e = 1: energy is lost only where the impact ends at its rest
            // speed v_r, each point dropping what it stores below a rebound
            // of v_r, E ≤ v_r²/(2 W_nn), W_nn = 2/kg for two 1 kg balls
            // struck centrally
            let ke0: f64 = bodies.iter().map(Body::kinetic_energy).sum();
            let lost = ke0 - probed.kinetic_energy_after;
            let v_r = at_rest_fraction().rest_speed;
            assert!(
                lost >= 0.0 && lost <= contacts.len() as f64 * v_r * v_r / 4.0,
                "{len} {lost}"
            );
            let (p0, p1) = (momentum(&bodies, None), momentum(&bodies, Some(&probed)));
            assert!((p1[0] - p0[0]).abs() < 1e-12, "{len} {p1:?}");
        }
    }

    #[test]
    fn invalid_input_is_rejected_before_stepping() {
        let (mut bodies, contacts) = wedge();
        bodies[0].velocity[0] = f64::NAN;
        let mut out = ImpactOutcome::default();
        let r = GroupSolver::default().solve_into(
            &bodies,
            &contacts,
            &ImpactSettings::default(),
            &FallbackPolicy::default(),
            &mut out,
        );
        assert!(matches!(r, Err(ImpactError::InvalidBody { .. })));
    }
}
