//! The resolver: [`ImpactSolver`], and the default integrator of the LZB law
//! in the impact's own time (docs/model.md §7).
//!
//! The law of docs/model.md §1–4 advances the state in the normal impulse of
//! a primary contact, dP_i = dP_p F_i/F_p. Dividing by the primary's force
//! F_p = dP_p/dt turns it into an ordinary differential equation in time
//! with the compressions q_i as state: the paper's scheme and this one follow
//! the same trajectory and differ only in how they step along it. In time
//! the right-hand side is smooth between switches and needs no `powf` for
//! α = 1 or 3/2, so a fifth-order pair takes tens of steps where a
//! second-order impulse step takes thousands, and the switches are located
//! on the interpolant instead of being landed on step by step.
//!
//! The method is the file list, one stage each:
//!
//! | file | stage |
//! | --- | --- |
//! | `data.rs` | what the stages share: frozen rows and patches, modes, switches, kinematics |
//! | `load.rs` | bodies, contact rows, friction patches, scales, the initial state |
//! | `law.rs` | the contact law: force, stored energy, dq/dt in compression and expansion |
//! | `rhs.rs` | dy/dt: normal forces, sliding friction, constraint forces; the probe of each mode's condition |
//! | `constraints.rs` | stuck patches and held points: A = J M⁻¹ Dᵀ factored once per set, solved per evaluation |
//! | `tableau.rs` | the Dormand–Prince 5(4) pair: stages, error estimate, interpolant |
//! | `rk.rs` | one step of the pair on the impact, its error norm |
//! | `events.rs` | the switches inside a step, located on the interpolant |
//! | `modes.rs` | the modes at an instant: touching points, stick and slip, held points |
//! | `run.rs` | step size control, free flight, the end of the impact |
//! | `energy.rs` | the outcome and its energy guard |

mod constraints;
mod data;
mod energy;
mod events;
mod law;
mod load;
mod modes;
mod rhs;
mod rk;
mod run;
mod tableau;

use super::impulse::{ImpulseScheme, ImpulseStepper};
use super::{
    capture, validate, Body, Contact, ImpactError, ImpactOutcome, ImpactSettings, StepControl,
};
use constraints::Constraints;
use data::{
    Axis, BodySlot, Clock, Layout, Patch, PatchMode, PatchState, PointState, Row, Scales, Suspect,
    Switch,
};

/// The fast-cycle bound of an e > 0 point as a fraction of
/// [`ImpactSettings::fast_cycle`] (docs/model.md §8, "Fast bounces at
/// e > 0"): holding such a point stops its approach as a plastic impact
/// would, which drops the rebound e·u of that approach u (first order in
/// the bound), where an e = 0 point has no rebound to drop. 0.03 keeps that
/// loss within the default tolerance's own error on the captured piles and
/// on Domino X blocks lying flat (0.1 does not on the latter).
const FAST_BOUNCE: f64 = 0.03;

/// With a rest speed v_r ([`ImpactSettings::rest_speed`]), an e = 0
/// point's load cycle is fast (its next cycles are taken by their limit,
/// the point held closed) once it moved the point's own rate by at most
/// this many times v_r, if that is more than `fast_cycle` · V
/// (docs/model.md §8). At the plugins' rest fraction 0.01 this is 0.3 of
/// the engine's impact threshold: a cycle slower than the approaches the
/// engine itself stops as resting contacts. On the bench's T row at the
/// plugins' default: 10, 30 and 100 take its median steps from 103 to 93,
/// 71 and 59, its error against the converged law from 3.1·10⁻³ to
/// 1.4·10⁻³, 2.2·10⁻³ and 3.3·10⁻³ (past main's at 100); with 30 the ideal
/// Domino T row's wave speed keeps its mean over a hundred starts
/// (docs/impact.md, "Steps per impact, round eleven").
const CYCLE_REST: f64 = 30.0;

/// Reusable LZB impact solver.
///
/// Keeps its buffers between calls, so resolving many impacts allocates only
/// when a problem is larger than any before it; the stepping loop itself never
/// allocates. [`StepControl`] chooses the integrator: the time-domain
/// Runge–Kutta solver (the default), or the paper's impulse stepping.
///
/// ```
/// use topple::impact::{Body, Contact, ContactMaterial, ImpactSettings, ImpactSolver};
/// let mut solver = ImpactSolver::new();
/// // Newton's cradle of three balls (m = 1 kg, I irrelevant), e = 1
/// let bodies = [
///     Body::new(1.0, 1.0).with_velocity([1.0, 0.0]),
///     Body::new(1.0, 1.0).with_position([0.2, 0.0]),
///     Body::new(1.0, 1.0).with_position([0.4, 0.0]),
/// ];
/// let hertz = ContactMaterial::hertz(1e9);
/// let contacts = [
///     Contact::new([Some(0), Some(1)], [0.1, 0.0], [1.0, 0.0], hertz),
///     Contact::new([Some(1), Some(2)], [0.3, 0.0], [1.0, 0.0], hertz),
/// ];
/// let out = solver.solve(&bodies, &contacts, &ImpactSettings::default()).unwrap();
/// let total: f64 = out.bodies.iter().map(|b| b.velocity[0]).sum();
/// assert!((total - 1.0).abs() < 1e-9); // momentum
/// assert!(out.kinetic_energy_after <= out.kinetic_energy_before);
/// assert!(out.steps < 100);
/// ```
#[derive(Debug, Default)]
pub struct ImpactSolver {
    integrator: Integrator,
    impulse: ImpulseStepper,
}

impl ImpactSolver {
    /// A solver with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Resolves one impact and returns a new [`ImpactOutcome`].
    pub fn solve(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
    ) -> Result<ImpactOutcome, ImpactError> {
        let mut out = ImpactOutcome::default();
        self.solve_into(bodies, contacts, settings, &mut out)?;
        Ok(out)
    }

    /// Resolves one impact into `out`, reusing its vectors.
    ///
    /// Errors: invalid input (checked before any stepping), the step limit, or
    /// a non-finite state. Fixed bodies keep their input velocity (they may be
    /// kinematic); a contact between two fixed bodies takes no part.
    pub fn solve_into(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        settings: &ImpactSettings,
        out: &mut ImpactOutcome,
    ) -> Result<(), ImpactError> {
        validate::check(bodies, contacts, settings)?;
        capture::record(bodies, contacts, settings);
        out.settling_evaluations = 0;
        match settings.step_control {
            // A lone contact: in the impulse its law is exact to rounding
            // (the velocities are linear in P and the energy's quadrature
            // has no error estimate to meet), a few steps
            StepControl::Adaptive { tolerance } if contacts.len() == 1 => self.impulse.solve_into(
                bodies,
                contacts,
                ImpulseScheme::Adaptive { tolerance },
                settings,
                out,
            ),
            StepControl::Adaptive { tolerance } => self
                .integrator
                .solve_into(bodies, contacts, tolerance, settings, out),
            StepControl::Fixed { impulse_step } => self.impulse.solve_into(
                bodies,
                contacts,
                ImpulseScheme::Fixed { impulse_step },
                settings,
                out,
            ),
            StepControl::AdaptiveImpulse { tolerance } => self.impulse.solve_into(
                bodies,
                contacts,
                ImpulseScheme::Adaptive { tolerance },
                settings,
                out,
            ),
        }
    }
}

/// The time-domain integrator (see the module docs). One per
/// [`ImpactSolver`]; its buffers are reused from impact to impact.
#[derive(Debug, Default)]
pub(crate) struct Integrator {
    // frozen (load.rs)
    layout: Layout,
    bodies: Vec<BodySlot>,
    rows: Vec<Row>,
    patches: Vec<Patch>,
    members: Vec<usize>,
    scales: Scales,
    tolerance: f64,
    min_step: f64,
    /// An e = 0 point is held after a load cycle that moved its rate by at
    /// most this much (m/s; ∞ with e0_hold): `fast_cycle` times the
    /// velocity scale, or with a rest speed at least [`CYCLE_REST`] times it.
    cycle_bound: f64,
    /// The same for the load cycles of e > 0 points (docs/model.md §8).
    fast_bounce: f64,
    /// The impact ends once everything left is slower than this (m/s,
    /// [`ImpactSettings::rest_speed`]; 0: never before its end).
    rest_speed: f64,
    // evolving
    y: Vec<f64>,
    clock: Clock,
    /// The controller's last proposal for a step in time (s), kept across
    /// segments whose own steps say nothing about it (a segment that ends a
    /// point's contact).
    pace: f64,
    points: Vec<PointState>,
    patch_modes: Vec<PatchMode>,
    patch_states: Vec<PatchState>,
    constraints: Constraints,
    constraints_dirty: bool,
    /// Right-hand-side evaluations spent settling modes in this impact
    /// ([`ImpactOutcome::settling_evaluations`]).
    settling: usize,
    // probe and events
    suspects: Vec<Suspect>,
    generation: u32,
    due: Vec<(f64, Switch)>,
    /// Held points and stuck patches watched by the present search, with
    /// the sign of each patch's friction.
    watched: Vec<(Suspect, f64)>,
    /// Digests of the modes met by the present settling (modes.rs).
    seen_modes: Vec<u64>,
    // scratch
    rk: tableau::Rk,
    order: Vec<usize>,
    tangents: Vec<Axis>,
    probe_state: Vec<f64>,
    probe_slope: Vec<f64>,
    /// δ̇ of every point at the last evaluation (rhs.rs, for its probe).
    rates: Vec<f64>,
    /// `probe_slope` holds dy/dt at `y` with the present modes: the last
    /// settling ended on a pass that changed nothing (or `ending_point`
    /// evaluated there), so the next step's first stage is a copy of it.
    slope_current: bool,
}

impl Integrator {
    /// Resolves one validated impact at `tolerance` into `out`.
    fn solve_into(
        &mut self,
        bodies: &[Body],
        contacts: &[Contact],
        tolerance: f64,
        settings: &ImpactSettings,
        out: &mut ImpactOutcome,
    ) -> Result<(), ImpactError> {
        self.load(bodies, contacts);
        self.tolerance = tolerance;
        self.cycle_bound = if settings.e0_hold {
            f64::INFINITY
        } else if settings.fast_cycle > 0.0 {
            (settings.fast_cycle * self.scales.velocity).max(CYCLE_REST * settings.rest_speed)
        } else {
            // every cycle followed (the paper's law)
            0.0
        };
        self.fast_bounce = settings.fast_cycle * FAST_BOUNCE;
        self.rest_speed = settings.rest_speed;
        self.min_step = 1e-14 * self.scales.time;
        let len = self.layout.len();
        self.probe_state.resize(len, 0.0);
        self.probe_slope.resize(len, 0.0);
        self.rates.resize(self.layout.contacts, 0.0);
        out.kinetic_energy_before = bodies.iter().map(Body::kinetic_energy).sum();
        out.steps = 0;
        out.rejected_steps = 0;
        self.settling = 0;
        let reason = self.run(settings.max_steps, out);
        out.settling_evaluations = self.settling;
        self.finish(bodies, reason?, out);
        Ok(())
    }

    /// Starts a new probe generation (a new step).
    fn clear_suspects(&mut self) {
        self.suspects.clear();
        self.generation = self.generation.wrapping_add(1);
    }

    fn suspect_point(&mut self, i: usize) {
        if self.points[i].seen != self.generation {
            self.points[i].seen = self.generation;
            self.suspects.push(Suspect::Point(i));
        }
    }

    fn suspect_patch(&mut self, p: usize) {
        if self.patch_states[p].seen != self.generation {
            self.patch_states[p].seen = self.generation;
            self.suspects.push(Suspect::Patch(p));
        }
    }
}
