//! What one run shows, measured from the block states alone (centre and
//! angle of every block), independently of the engine's own report.

use crate::impact::audit::AuditSummary;
use crate::validate::box_overlap;

/// A block counts as fallen past this tilt (rad) once it lies on what it
/// leans towards ([`LYING_GAP`], [`LYING_TIME`]). A block first touches the
/// next one at a tilt asin(s/h) < π/4 for every s/h the sweep draws (< 0.6),
/// and past π/4 it mostly lies on a block that only moves forward. Not
/// always: a block that first meets its neighbour near π/4 (s/h near 0.6)
/// can strike it past π/4 and rebound off it (Table 1's e1 reverses the
/// striker); it never lay on it, so it had not fallen. A leaning train at
/// small spacing rests near π/4 (face to face at acos(d/(s + d)), 50° for
/// Domino X at s/h 0.1) and rocks about it; a Rapier run's drop of the
/// fallen count is therefore also checked against the same row in the
/// reference engine (`docs/stress.md`).
pub const FALLEN_TILT: f64 = std::f64::consts::FRAC_PI_4;

/// A block past [`FALLEN_TILT`] touches a block it leans towards (or lies
/// on the ground with two corners) when the gap between them is at most this
/// fraction of the block height: separating axes of the two outlines from
/// the poses. The reference closes contacts to 10⁻⁶ h and Rapier's rest in
/// its allowed error (−0.005 h); a block rebounding at 2 rad/s opens 10⁻³ h
/// in half a millisecond.
pub const LYING_GAP: f64 = 1e-3;

/// … and lies on it once it has touched it at every look for this long (s)
/// and at two looks at least. An impact lasts microseconds (a Rapier step at
/// most, 1/30 s); a block that struck its neighbour and rebounds leaves it at
/// once, one that lies on it stays.
pub const LYING_TIME: f64 = 0.01;

/// A topple Rapier run's drop of the fallen count held against native
/// Rapier: the run and [`NEARBY_RUNS`] nearby starts
/// (block 1's push changed by k · [`ROW_NEARBY_PUSH`]), each in topple's
/// engine and in native Rapier of the same build at the same step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NativeRockBack {
    /// topple's least [`Observation::stood_up_rock_back`] over its starts
    /// (rad; 0 where a start stands no block up).
    pub topple_least: f64,
    /// native's largest [`Observation::fallen_rock_back`] over its starts
    /// (rad): how far it rocks a fallen block back, across π/4 or not.
    pub native_most: f64,
    /// native's largest [`Observation::fallen_drop`] over its starts.
    pub native_drop: usize,
}

/// Change of block 1's dimensionless push θ̇₁ √(h/g) between nearby starts
/// of a row (about 10⁻⁶ √(gh) m/s at its top: far below any speed a step
/// resolves, far above the round-off of f64 speeds).
pub const ROW_NEARBY_PUSH: f64 = 1e-6;

/// How many nearby starts a run the check cannot judge from one start is
/// run from, besides its own: a row whose fallen count dropped (above), a
/// scene deeper than native Rapier (`scene::run`).
pub const NEARBY_RUNS: usize = 6;

/// The observations of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Observation {
    /// A block state (or a report value) was NaN or infinite.
    pub non_finite: bool,
    /// Largest overlap of two blocks (any two, not only neighbours), or of a
    /// block with the ground, over the block height.
    pub penetration: f64,
    /// Where the largest penetration was: "blocks i/j" or "block i/ground"
    /// (1-based), at which time.
    pub penetration_at: String,
    /// The row as it was at the largest penetration and up to three looks
    /// before it, ten looks apart, oldest first (time in s; centre and
    /// angle of every block), to draw it (`topple stress --combo K --draw`).
    pub deepest: Vec<(f64, Vec<[f64; 3]>)>,
    /// The same looks around the first drop of the fallen count.
    pub dropped: Vec<(f64, Vec<[f64; 3]>)>,
    /// Largest drop of the fallen count between two observed instants: the
    /// fallen blocks that came back below [`FALLEN_TILT`] at one look.
    pub fallen_drop: usize,
    /// Blocks fallen at the end (past [`FALLEN_TILT`], and lying on a block
    /// or on the ground since they passed it).
    pub fallen: usize,
    /// For a Rapier run whose fallen count dropped: the largest drop of the
    /// same row in the reference engine (`None` if it could not be run).
    pub reference_fallen_drop: Option<usize>,
    /// Largest rock-back (rad) of a block once past [`FALLEN_TILT`]: its
    /// largest tilt so far less its tilt now, over every look. A block
    /// that strikes its neighbour rebounds (Table 1's e1 reverses the
    /// striker, the paper's reversed blocks), by a degree or two.
    pub fallen_rock_back: f64,
    /// The same, only for fallen blocks whose rock-back took them back
    /// below [`FALLEN_TILT`] (0 if none did): how far a block that stood up
    /// again had come back from its largest tilt.
    pub stood_up_rock_back: f64,
    /// Blocks that passed [`FALLEN_TILT`] and came back below it without
    /// having lain on anything in between (a rebound off the block struck):
    /// reported, not a drop.
    pub rebounds: usize,
    /// For a Rapier run whose fallen count dropped: the reference engine's
    /// [`Observation::fallen_rock_back`] on the same row (`None` if it could
    /// not be run).
    pub reference_rock_back: Option<f64>,
    /// For a topple Rapier run whose fallen count dropped where the
    /// reference does not explain it: the same row, perturbation and step
    /// from nearby starts, in topple's engine and in native Rapier of the
    /// same build ([`NativeRockBack`]); `None` if not run.
    pub native_rock_back: Option<NativeRockBack>,
    /// Fallen blocks (1-based) that came back below [`FALLEN_TILT`], in the
    /// order they first did.
    pub stood_up: Vec<usize>,
    /// Blocks hit by the wave.
    pub hits: usize,
    /// The run did not end within its budget (its engine's own limits or the
    /// sweep's budget of CPU time).
    pub over_budget: bool,
    /// Wall-clock time of the run (s), reported.
    pub wall: f64,
    /// CPU time of the run (s), the thread that ran it: what the budget
    /// bounds.
    pub cpu: f64,
    /// The impacts, checked independently (see [`crate::impact::audit`]).
    pub audit: AuditSummary,
    /// An error the engine returned (the run could not be done).
    pub error: Option<String>,
}

/// One block towards the fallen count.
#[derive(Clone, Copy, Debug, Default)]
struct Lying {
    /// Past [`FALLEN_TILT`] since its last look below it.
    past: bool,
    /// Since when (time, look) it has touched what it leans on, while past.
    since: Option<(f64, usize)>,
    /// It has lain on a block or the ground since it passed: fallen.
    lain: bool,
}

/// Tracks the states of a row of blocks of height `h`, thickness `d`
/// standing on the ground at y = 0.
///
/// ```
/// use topple::stress::RowWatch;
/// // blocks 0.1 m × 0.02 m; the third lies on the first (they are not
/// // neighbours), 5 mm deep
/// let mut w = RowWatch::new(0.1, 0.02);
/// w.look(0.0, &[[0.0, 0.05, 0.0], [0.2, 0.05, 0.0], [0.015, 0.05, 0.0]]);
/// assert!((w.seen.penetration - 0.05).abs() < 1e-12);
/// assert!(w.seen.penetration_at.starts_with("blocks 1/3"));
/// ```
#[derive(Clone, Debug)]
pub struct RowWatch {
    half: [f64; 2],
    h: f64,
    /// Centres closer than this (the block's diagonal) may overlap.
    reach: f64,
    /// The last looks, oldest first (for `Observation::deepest`).
    recent: std::collections::VecDeque<(f64, Vec<[f64; 3]>)>,
    /// Largest tilt (rad, absolute) of every block so far.
    peak: Vec<f64>,
    /// Every block's state towards the fallen count.
    lying: Vec<Lying>,
    looks: usize,
    /// What has been seen so far.
    pub seen: Observation,
}

impl RowWatch {
    /// A watch for blocks of height `h` and thickness `d` (m).
    pub fn new(h: f64, d: f64) -> Self {
        RowWatch {
            half: [0.5 * d, 0.5 * h],
            h,
            reach: h.hypot(d),
            recent: std::collections::VecDeque::new(),
            peak: Vec::new(),
            lying: Vec::new(),
            looks: 0,
            seen: Observation::default(),
        }
    }

    /// Looks at the row at `time` (s): (x, y, angle) of every block, in
    /// row order.
    pub fn look(&mut self, time: f64, blocks: &[[f64; 3]]) {
        if blocks.iter().flatten().any(|v| !v.is_finite()) {
            self.seen.non_finite = true;
            return;
        }
        self.looks += 1;
        if self.recent.len() == 31 {
            self.recent.pop_front();
        }
        self.recent.push_back((time, blocks.to_vec()));
        let mut worst = (0.0, String::new());
        // every pair within reach: in a pile a block can lie on one that is
        // not its neighbour
        for (i, a) in blocks.iter().enumerate() {
            for (j, b) in blocks.iter().enumerate().skip(i + 1) {
                if (b[0] - a[0]).hypot(b[1] - a[1]) >= self.reach {
                    continue;
                }
                let depth = box_overlap(([a[0], a[1]], a[2]), ([b[0], b[1]], b[2]), self.half);
                if depth > worst.0 {
                    worst = (depth, format!("blocks {}/{}", i + 1, j + 1));
                }
            }
        }
        for (i, b) in blocks.iter().enumerate() {
            let (s, c) = b[2].sin_cos();
            let lowest = b[1] - self.half[0] * s.abs() - self.half[1] * c.abs();
            if -lowest > worst.0 {
                worst = (-lowest, format!("block {}/ground", i + 1));
            }
        }
        if worst.0 / self.h > self.seen.penetration {
            self.seen.penetration = worst.0 / self.h;
            self.seen.penetration_at = format!("{} at t = {time:.4} s", worst.1);
            self.seen.deepest = self.moments();
        }
        self.peak.resize(blocks.len(), 0.0);
        self.lying.resize(blocks.len(), Lying::default());
        let mut drop = 0;
        for k in 0..blocks.len() {
            let tilt = blocks[k][2].abs();
            let peak = &mut self.peak[k];
            *peak = peak.max(tilt);
            if *peak > FALLEN_TILT {
                let back = *peak - tilt;
                self.seen.fallen_rock_back = self.seen.fallen_rock_back.max(back);
            }
            let state = &mut self.lying[k];
            if tilt <= FALLEN_TILT {
                if state.lain {
                    drop += 1;
                    let back = self.peak[k] - tilt;
                    self.seen.stood_up_rock_back = self.seen.stood_up_rock_back.max(back);
                    if !self.seen.stood_up.contains(&(k + 1)) {
                        self.seen.stood_up.push(k + 1);
                    }
                } else if state.past {
                    self.seen.rebounds += 1;
                }
                *state = Lying::default();
                continue;
            }
            state.past = true;
            if state.lain {
                continue;
            }
            let touching = self.touches(blocks, k);
            let state = &mut self.lying[k];
            if touching {
                let since = *state.since.get_or_insert((time, self.looks));
                if time - since.0 >= LYING_TIME && self.looks > since.1 {
                    state.lain = true;
                }
            } else {
                state.since = None;
            }
        }
        if drop > 0 && self.seen.dropped.is_empty() {
            self.seen.dropped = self.moments();
        }
        self.seen.fallen_drop = self.seen.fallen_drop.max(drop);
        self.seen.fallen = self.lying.iter().filter(|l| l.lain).count();
    }

    /// Whether block `k` touches (within [`LYING_GAP`] h) a block whose
    /// centre lies on the side it leans towards, or the ground with two of
    /// its corners (it lies on its face).
    fn touches(&self, blocks: &[[f64; 3]], k: usize) -> bool {
        let b = blocks[k];
        let tol = LYING_GAP * self.h;
        // φ counter-clockwise: a negative angle leans towards +x
        let side = -b[2].signum();
        let on_block = blocks.iter().enumerate().any(|(j, o)| {
            j != k
                && (o[0] - b[0]) * side > 0.0
                && (o[0] - b[0]).hypot(o[1] - b[1]) < self.reach
                && box_overlap(([b[0], b[1]], b[2]), ([o[0], o[1]], o[2]), self.half) >= -tol
        });
        let (s, c) = b[2].sin_cos();
        let corners_down = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .filter(|(u, v)| b[1] + s * u * self.half[0] + c * v * self.half[1] <= tol)
            .count();
        on_block || corners_down >= 2
    }

    /// The last look and up to three before it, ten looks apart, oldest
    /// first.
    fn moments(&self) -> Vec<(f64, Vec<[f64; 3]>)> {
        let last = self.recent.len().saturating_sub(1);
        (0..4)
            .rev()
            .filter_map(|k| last.checked_sub(10 * k))
            .filter_map(|k| self.recent.get(k).cloned())
            .collect()
    }
}
