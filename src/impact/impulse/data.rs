//! The data layout every stage shares: the stepper with its buffers, and per
//! contact one [`Row`] of frozen geometry and material, one [`ContactState`]
//! that evolves (saved and restored whole by the predictor and by a rejected
//! step) and one [`Scratch`] of the current step; per body one [`BodySlot`]
//! and one `[vx, vy, ω]`, the fixed world in the last slot. Also the
//! kinematics of a contact row.
//!
//! Equations: the normal rate δ̇ = n·(v_b + ω_b × r_b − v_a − ω_a × r_a)
//! (negative while approaching, m/s) and its tangential twin; an impulse p
//! along a direction changes the velocities by ∓ M⁻¹ (dir, r × dir) p.

/// The impulse-stepping integrator (see the module docs). Keeps its buffers
/// between impacts; the stepping loop never allocates.
///
/// P₀, the impulse scale of [`crate::impact::StepControl::Fixed`], is the larger of the
/// magnitude of the free bodies' total linear momentum (the paper's
/// definition) and the largest impulse that would stop one approaching contact
/// on its own (|δ̇_i| / W_ii); the second matters when the momentum is zero, as
/// for two bodies meeting head-on.
#[derive(Debug, Default)]
pub(crate) struct ImpulseStepper {
    pub(super) rows: Vec<Row>,
    pub(super) body_slots: Vec<BodySlot>,
    /// Body velocities [vx, vy, ω]; the last slot is the world.
    pub(super) velocity: Vec<[f64; 3]>,
    /// Trial velocities (landing prediction).
    pub(super) trial: Vec<[f64; 3]>,
    pub(super) state: Vec<ContactState>,
    pub(super) scratch: Vec<Scratch>,
    /// Improved Euler: state saved before the half step.
    pub(super) mid_velocity: Vec<[f64; 3]>,
    pub(super) mid_state: Vec<ContactState>,
    pub(super) scales: Scales,
    /// Impact time elapsed so far (s), from the contact law.
    pub(super) elapsed: f64,
    /// See [`ImpactSettings::e0_hold`].
    ///
    /// [`ImpactSettings::e0_hold`]: super::super::ImpactSettings::e0_hold
    pub(super) e0_hold: bool,
    /// See [`ImpactSettings::rest_speed`] (m/s; 0: never before its end).
    ///
    /// [`ImpactSettings::rest_speed`]: super::super::ImpactSettings::rest_speed
    pub(super) rest_speed: f64,
    /// Adaptive mode: state saved before a trial step, restored on rejection.
    pub(super) saved_velocity: Vec<[f64; 3]>,
    pub(super) saved_state: Vec<ContactState>,
    /// The impulse (N·s) below which a landing is not worth a step:
    /// `MIN_LANDING` (control.rs) times the paper's step 10⁻⁴ P₀ in adaptive mode, so
    /// that large adaptive steps do not skip events.
    pub(super) landing_impulse: f64,
    /// Local error estimate of the last full step (adaptive mode), relative
    /// to the velocity scale.
    pub(super) step_error: f64,
    /// Adaptive mode is running (the full steps estimate their error).
    pub(super) adaptive: bool,
    /// The Gauss nodes warped for an end where E = 0 (see
    /// `impact_time`, energy.rs), for the contacts of `warp.0`'s exponent.
    pub(super) warp: (f64, [NodeWarp; 4]),
}

/// One contact's working data for the current step (Box2D's contact-solver
/// layout: every stage loads what it needs of a point into locals, solves,
/// and stores back). Reset at the start of each impact.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Scratch {
    /// δ̇ at the start of the step (m/s).
    pub rate: f64,
    /// δ̇ change over the full (unlanded) step; after the energies, the
    /// rate at the step's end (m/s).
    pub rate_change: f64,
    /// Normal increment of the step (N·s).
    pub increment: f64,
    /// F_i(E_i) (N) of the energies at the step's start, 0 where unloaded;
    /// set by the predictor, reused by the error estimate.
    pub start_force: f64,
    /// Explicit-Euler increment of the error estimate (adaptive mode, N·s).
    pub euler_increment: f64,
    /// Energy at mid-step, predicted by the half step (J).
    pub mid_energy: f64,
    /// Tangential and held normal increments of the step (N·s).
    pub tangent_step: f64,
    pub held_step: f64,
    /// Without slip at the step's start.
    pub stuck_at_start: bool,
    /// Releases its last bit of energy without a step.
    pub released: bool,
    /// Its gap closes without a step.
    pub closing: bool,
}

/// Inverse mass (1/kg) and inverse inertia (1/(kg·m²)) of a body slot: 0
/// for fixed bodies and the world.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BodySlot {
    pub inv_mass: f64,
    pub inv_inertia: f64,
}

/// Frozen geometry and material of one contact.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Row {
    /// Body slots (the world is the last slot).
    pub a: usize,
    pub b: usize,
    pub normal: [f64; 2],
    pub tangent: [f64; 2],
    /// r×n and r×t for each body (r from the centre of mass to the point).
    pub a_rn: f64,
    pub a_rt: f64,
    pub b_rn: f64,
    pub b_rt: f64,
    /// Diagonal entries of the Delassus operator along n and t (1/kg).
    pub w_nn: f64,
    pub w_tt: f64,
    /// c = (α+1)^(α/(α+1)) k^(1/(α+1)), so F(E) = c E^(α/(α+1)).
    pub force_coeff: f64,
    /// α/(α+1).
    pub power: f64,
    pub exponent: f64,
    pub restitution: f64,
    pub friction: f64,
    pub stick_friction: f64,
    /// False when neither body can move: such a contact takes no part.
    pub movable: bool,
}

/// A direction of impulse with its moment arms r×dir on the two bodies.
#[derive(Clone, Copy, Debug)]
pub(super) struct Axis {
    pub dir: [f64; 2],
    pub arm_a: f64,
    pub arm_b: f64,
}

/// Evolving state of one contact.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ContactState {
    /// Stored potential energy E (J).
    pub energy: f64,
    pub normal_impulse: f64,
    pub tangent_impulse: f64,
    pub peak_energy: f64,
    /// Separation opened after release (m); the contact is closed while 0.
    pub gap: f64,
    /// Stick (true) or slip (false) for the friction law.
    pub sticking: bool,
    /// e = 0 contact whose compression has ended without separating: held
    /// closed by a non-negative impulse (the sliding-mode limit of e = 0).
    pub held: bool,
}

/// Scales of one impact, fixed at its start.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Scales {
    /// P₀ (N·s), see [`crate::impact::StepControl::Fixed`].
    pub impulse: f64,
    /// Largest approach speed at the start (m/s).
    pub velocity: f64,
    /// Rates above −threshold count as not approaching (m/s).
    pub threshold: f64,
}

impl Row {
    #[inline]
    pub fn normal_axis(&self) -> Axis {
        Axis {
            dir: self.normal,
            arm_a: self.a_rn,
            arm_b: self.b_rn,
        }
    }

    #[inline]
    pub fn tangent_axis(&self) -> Axis {
        Axis {
            dir: self.tangent,
            arm_a: self.a_rt,
            arm_b: self.b_rt,
        }
    }

    /// δ̇ = n·(v_b + ω_b × r_b − v_a − ω_a × r_a) (m/s).
    #[inline]
    pub fn normal_rate(&self, v: &[[f64; 3]]) -> f64 {
        let (va, vb) = (v[self.a], v[self.b]);
        self.normal[0] * (vb[0] - va[0]) + self.normal[1] * (vb[1] - va[1]) + vb[2] * self.b_rn
            - va[2] * self.a_rn
    }

    /// Tangential relative velocity along t (m/s).
    #[inline]
    pub fn tangent_rate(&self, v: &[[f64; 3]]) -> f64 {
        let (va, vb) = (v[self.a], v[self.b]);
        self.tangent[0] * (vb[0] - va[0]) + self.tangent[1] * (vb[1] - va[1]) + vb[2] * self.b_rt
            - va[2] * self.a_rt
    }

    /// Applies impulse `p` (N·s) along `axis` to the row's bodies: −p on a,
    /// +p on b.
    #[inline]
    pub fn apply(&self, axis: Axis, p: f64, slots: &[BodySlot], v: &mut [[f64; 3]]) {
        let Axis { dir, arm_a, arm_b } = axis;
        let (sa, sb) = (slots[self.a], slots[self.b]);
        let (ma, ia) = (sa.inv_mass * p, sa.inv_inertia * p);
        let va = &mut v[self.a];
        va[0] -= ma * dir[0];
        va[1] -= ma * dir[1];
        va[2] -= ia * arm_a;
        let (mb, ib) = (sb.inv_mass * p, sb.inv_inertia * p);
        let vb = &mut v[self.b];
        vb[0] += mb * dir[0];
        vb[1] += mb * dir[1];
        vb[2] += ib * arm_b;
    }

    /// The contact has friction along its tangent.
    #[inline]
    pub fn has_friction(&self) -> bool {
        self.w_tt > 0.0 && (self.friction > 0.0 || self.stick_friction > 0.0)
    }

    /// Unbounded friction (μ = ∞, [`ContactMaterial::no_slip`]): the
    /// contact never slides while it takes normal impulse.
    ///
    /// [`ContactMaterial::no_slip`]: super::super::ContactMaterial::no_slip
    #[inline]
    pub fn no_slip(&self) -> bool {
        self.friction == f64::INFINITY
    }
}

/// Gauss–Legendre nodes on [0, 1] and weights (4 points, exact for
/// polynomials of degree 7).
pub(super) const GAUSS_4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_87, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// A Gauss node s warped by σ = s^k: (s^k, k s^(k−1)).
pub(super) type NodeWarp = (f64, f64);

/// The Gauss nodes warped by σ = s^k (k = α + 1 of the contact law).
pub(super) fn warped_nodes(k: f64) -> [NodeWarp; 4] {
    GAUSS_4.map(|(node, _)| (node.powf(k), k * node.powf(k - 1.0)))
}
