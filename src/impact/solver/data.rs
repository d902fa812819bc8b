//! The solver's data, shared by its stages: the impact's frozen bodies,
//! rows, patches, scales and state layout (set up in load.rs), the modes and
//! per-point state that evolve between switches, the switches themselves,
//! and the kinematics every stage reads (a force pushed along an axis, a
//! relative rate). Nothing here refers to the solver itself, so the stage
//! files depend on it and it on none of them.

use super::law::Law;

/// A body slot: inverse mass and inertia (0 for fixed bodies and the world)
/// and the radius of gyration ρ = √(I/m) that turns ω errors into speeds.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BodySlot {
    pub inv_mass: f64,
    pub inv_inertia: f64,
    pub gyration: f64,
}

/// A direction of impulse on a pair of bodies with its moment arms r × dir.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Axis {
    pub dir: [f64; 2],
    pub arm_a: f64,
    pub arm_b: f64,
}

impl Axis {
    /// `self − c · other` (the direction of a held normal force that drags
    /// sliding friction along).
    pub fn minus(self, c: f64, other: Axis) -> Axis {
        Axis {
            dir: [
                self.dir[0] - c * other.dir[0],
                self.dir[1] - c * other.dir[1],
            ],
            arm_a: self.arm_a - c * other.arm_a,
            arm_b: self.arm_b - c * other.arm_b,
        }
    }
}

/// Frozen geometry and law of one contact point.
#[derive(Clone, Copy, Debug)]
pub(super) struct Row {
    /// Body slots; the first body takes −F, the second +F.
    pub a: usize,
    pub b: usize,
    pub normal: Axis,
    /// The direction F pushes along: the normal, plus −μ s times the
    /// tangent while the point's patch slides with sign s (kept by
    /// `Integrator::set_patch`), and the friction factor −μ s itself.
    pub drive: Axis,
    pub slide: f64,
    /// 1/m and 1/I of body a, then of body b (0 for fixed bodies).
    pub inverse: [f64; 4],
    pub law: Law,
    /// Friction patch (see [`Patch`]).
    pub patch: usize,
    /// W_nn = J_n M⁻¹ J_nᵀ (1/kg).
    pub w_nn: f64,
    /// Compression that would store the energy of an approach at the
    /// impact's velocity scale (m): the scale of q's error.
    pub q_scale: f64,
    /// Compressions within ± this (10⁻¹² q_scale) count as zero (m).
    pub q_zero: f64,
    /// A point whose compression stays below this (10⁻⁶ q_scale, m) has not
    /// loaded: when it separates its (negligible) energy is not booked as
    /// a compression that ended.
    pub q_load: f64,
    /// False when neither body can move: such a contact takes no part.
    pub movable: bool,
}

/// Contacts of one body pair whose tangential rows are the same (the points
/// of one flat face: r × t is the distance of the face's line from each
/// centre of mass, the same for every point on it). Coulomb's law per point
/// with one shared slip velocity is exactly Coulomb's law of the patch with
/// the summed normal force, so stick and slip are decided per patch: its
/// constraint rows stay independent where the points' would not.
#[derive(Clone, Copy, Debug)]
pub(super) struct Patch {
    pub a: usize,
    pub b: usize,
    pub tangent: Axis,
    /// W_tt (1/kg).
    pub w_tt: f64,
    /// Sliding μ and the sticking bound max(μ_s, μ); μ = ∞: no slip.
    pub friction: f64,
    pub stick_bound: f64,
    /// Members: `members[first..first + count]`.
    pub first: usize,
    pub count: usize,
}

impl Patch {
    pub fn no_slip(&self) -> bool {
        self.friction == f64::INFINITY
    }

    pub fn frictionless(&self) -> bool {
        self.w_tt <= 0.0 || (self.friction == 0.0 && self.stick_bound == 0.0)
    }
}

/// Scales of one impact, fixed at its start.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Scales {
    /// Largest approach speed at the start (m/s).
    pub velocity: f64,
    /// Normal and tangential rates within ± this are taken as zero (m/s):
    /// rounding left after landing on a switch.
    pub rate: f64,
    /// A point that starts to load approaching faster than this (10⁻³ of
    /// the velocity scale, m/s) starts a segment of its own (its force grows
    /// as t^α, see `Variable::Root`).
    pub onset: f64,
    /// The shortest time scale of the points approaching at the start (s,
    /// law.rs).
    pub time: f64,
    /// Accelerations within ± this are taken as zero (m/s²): the rate
    /// threshold over the time scale. A sliding patch whose slip and slip
    /// acceleration are both zero to this rounding has its slip fixed by
    /// other rows (a closed loop of stuck patches) and keeps its mode.
    pub accel: f64,
}

/// Offsets of the state vector's parts.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Layout {
    /// Body slots, the world included.
    pub bodies: usize,
    pub contacts: usize,
}

impl Layout {
    pub fn q(&self, i: usize) -> usize {
        3 * self.bodies + i
    }
    pub fn pn(&self, i: usize) -> usize {
        3 * self.bodies + self.contacts + i
    }
    pub fn pt(&self, i: usize) -> usize {
        3 * self.bodies + 2 * self.contacts + i
    }
    /// The time (s) since the impact started.
    pub fn time(&self) -> usize {
        3 * (self.bodies + self.contacts)
    }
    pub fn len(&self) -> usize {
        3 * (self.bodies + self.contacts) + 1
    }
}

/// Adds force `f` along `axis` (−f on body `a`, +f on body `b`) to the
/// accelerations `acc` ([ax, ay, α] per body slot).
#[inline]
pub(super) fn push(bodies: &[BodySlot], a: usize, b: usize, axis: &Axis, f: f64, acc: &mut [f64]) {
    let (sa, sb) = (&bodies[a], &bodies[b]);
    let inverse = [sa.inv_mass, sa.inv_inertia, sb.inv_mass, sb.inv_inertia];
    push_with(inverse, a, b, axis, f, acc);
}

/// [`push`] with the bodies' inverse masses and inertias given.
#[inline]
pub(super) fn push_with(
    inverse: [f64; 4],
    a: usize,
    b: usize,
    axis: &Axis,
    f: f64,
    acc: &mut [f64],
) {
    push_slots(inverse, a, b, axis, f, acc.as_chunks_mut::<3>().0);
}

/// [`push_with`] on the accelerations as [ax, ay, α] per body slot (one
/// bounds check per body).
#[inline]
pub(super) fn push_slots(
    inverse: [f64; 4],
    a: usize,
    b: usize,
    axis: &Axis,
    f: f64,
    acc: &mut [[f64; 3]],
) {
    let [ma, ia, mb, ib] = inverse;
    let pa = &mut acc[a];
    pa[0] -= ma * f * axis.dir[0];
    pa[1] -= ma * f * axis.dir[1];
    pa[2] -= ia * f * axis.arm_a;
    let pb = &mut acc[b];
    pb[0] += mb * f * axis.dir[0];
    pb[1] += mb * f * axis.dir[1];
    pb[2] += ib * f * axis.arm_b;
}

/// [`rate`] on the velocities as [vx, vy, ω] per body slot (one bounds
/// check per body).
#[inline]
pub(super) fn slot_rate(v: &[[f64; 3]], a: usize, b: usize, axis: &Axis) -> f64 {
    let (va, vb) = (&v[a], &v[b]);
    axis.dir[0] * (vb[0] - va[0]) + axis.dir[1] * (vb[1] - va[1]) + vb[2] * axis.arm_b
        - va[2] * axis.arm_a
}

/// Relative rate along `axis` of body `b` against body `a` in the velocities
/// (or accelerations) `v`: dir·(v_b − v_a) + ω_b arm_b − ω_a arm_a.
#[inline]
pub(super) fn rate(v: &[f64], a: usize, b: usize, axis: &Axis) -> f64 {
    slot_rate(v.as_chunks::<3>().0, a, b, axis)
}

/// Normal rate δ̇ of a row (m/s).
#[inline]
pub(super) fn normal_rate(row: &Row, v: &[f64]) -> f64 {
    rate(v, row.a, row.b, &row.normal)
}

/// What a point does at present.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum PointMode {
    /// The compression law: dq/dt = −δ̇ and F = k max(q, 0)^α. It covers
    /// the open gap (q < 0, no force), the touching point (q = 0: it loads
    /// as soon as it is pushed in, and separates without a switch) and the
    /// compression phase (δ̇ ≤ 0).
    #[default]
    Compress,
    /// The expansion law of a point with e > 0 after its compression ended:
    /// dq/dt = −δ̇/e², F = k q^α.
    Expand,
    /// Held closed by a force λ ≥ 0 that keeps δ̇ constant (zero, to the
    /// rounding of the switch).
    Held,
}

/// What a friction patch does at present.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) enum PatchMode {
    /// No friction: a frictionless patch, or a patch without slip that
    /// carries no load.
    #[default]
    Idle,
    /// No slip: a constraint row.
    Stick,
    /// Slipping with sign s of v_t: friction −μ s N.
    Slide(f64),
}

/// The evolving state of one point besides y.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct PointState {
    pub(super) mode: PointMode,
    /// F = k q^α and the held force λ of the last evaluation (N).
    pub(super) force: f64,
    pub(super) held_force: f64,
    /// Largest compression reached (m).
    pub(super) peak: f64,
    /// q ≤ 0 at the start of the present step, or within the rounding of
    /// zero while a patch waits for its load (an onset is watched).
    pub(super) open: bool,
    /// The compression at which the onset of an open point is a switch:
    /// 0 for a gap, the rounding of zero (`Row::q_zero`) for a point that
    /// starts the step within it, where it does not carry load yet
    /// (modes.rs, `carries_load`) (m).
    pub(super) close_at: f64,
    /// An e = 0 point whose energy has just been lost after a load cycle
    /// short enough to be held closed from now on (see
    /// [`ImpactSettings::fast_cycle`]).
    pub(super) released: bool,
    /// An e > 0 point whose last load cycle (from one release to the next:
    /// letting go, or a hold ending) moved its own rate by at most
    /// `fast_cycle` of the velocity scale: its next closing, if it is
    /// pushed in and approaches no faster than that, is taken by the limit
    /// of the cycles (held closed, docs/model.md §8).
    pub(super) fast_rebound: bool,
    /// P_n (N·s) at which the hold of an e > 0 point is spent: beyond one
    /// fast cycle's swing the push is no longer a fast cycle, and the point
    /// loads under the law again (∞ for e = 0 and while not held).
    pub(super) hold_limit: f64,
    /// P_n at the start of the present load cycle (N·s).
    pub(super) cycle_start: f64,
    /// Time (s) at which the point last switched: it does not switch again
    /// at that same instant (a switch within 10⁻⁹ of a step is rounding),
    /// and is not closed again at it unless it approaches.
    pub(super) switched_at: f64,
    /// Time (s) at which the point's gap last closed (a `Switch::Closes`
    /// landed on): a step that starts there finds it a rounding into
    /// contact, already loading, and does not close it again.
    pub(super) closed_at: f64,

    /// Probe generation in which the point was last noted.
    pub(super) seen: u32,
}

/// A patch's normal load N = Σ (F + λ) and stuck friction force of the last
/// evaluation (N), and its switch bookkeeping (see [`PointState`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct PatchState {
    pub(super) normal: f64,
    pub(super) friction: f64,
    pub(super) seen: u32,
    pub(super) switched_at: f64,
}

impl Default for PatchState {
    fn default() -> Self {
        PatchState {
            normal: 0.0,
            friction: 0.0,
            seen: 0,
            switched_at: f64::NAN,
        }
    }
}

/// The independent variable x of the present segment.
///
/// The force of a point grows as (t − t₀)^α where it starts to load while
/// approaching, and falls as (t₁ − t)^α where it lets go while separating;
/// no polynomial in t follows either, so a fifth-order step loses its order
/// there. A segment that starts with a point loading while it approaches
/// uses x = √(t − t₀), in which that force is a polynomial for α = 1 and 3/2
/// (and far smoother for any other α). A segment that ends with a point
/// letting go uses x = σ₀ − √q of that point: q = (σ₀ − x)² exactly, its
/// force likewise, and the point lets go at x = σ₀, where the segment ends
/// without any search. Every other segment uses x = t − t₀. The time itself
/// is the last component of the state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) enum Variable {
    /// x = t − t₀.
    #[default]
    Time,
    /// x = √(t − t₀).
    Root,
    /// x = σ₀ − √q of point `point`, which is expanding (e > 0).
    End { point: usize, sigma: f64 },
}

/// The present segment's variable and x at the present state.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Clock {
    pub(super) variable: Variable,
    pub(super) x: f64,
}

/// A switch located inside a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Switch {
    /// A point's compression ends.
    CompressionEnds(usize),
    /// An expanding point is pushed in again.
    Recompresses(usize),
    /// A loaded point's compression reaches zero.
    LetsGo(usize),
    /// An open point's gap closes.
    Closes(usize),
    /// A sliding patch's slip reaches zero.
    SlipStops(usize),
    /// The hold of an e > 0 point has taken one fast cycle's swing: the
    /// point loads under the law from here (docs/model.md §8).
    HoldSpent(usize),
}

/// A point or a patch noted by the probe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Suspect {
    Point(usize),
    Patch(usize),
}
