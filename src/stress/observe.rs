//! What one run shows, measured from the block states alone (centre and
//! angle of every block), independently of the engine's own report.

use crate::impact::audit::AuditSummary;
use crate::validate::box_overlap;

/// A block counts as fallen past this tilt (rad). A block first touches the
/// next one at a tilt asin(s/h) < π/4 for every s/h the sweep draws (< 0.6),
/// and past π/4 it mostly lies on a block that only moves forward. Not
/// always: a block that first meets its neighbour near π/4 (s/h near 0.6)
/// can rebound off it, and a leaning train at small spacing rests near π/4
/// (face to face at acos(d/(s + d)), 50° for Domino X at s/h 0.1) and rocks
/// about it. A Rapier run's drop of the fallen count is therefore checked
/// against the same row in the reference engine (`docs/stress.md`).
pub const FALLEN_TILT: f64 = std::f64::consts::FRAC_PI_4;

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
    /// Largest drop of the fallen count between two observed instants.
    pub fallen_drop: usize,
    /// Blocks fallen at the end.
    pub fallen: usize,
    /// For a Rapier run whose fallen count dropped: the largest drop of the
    /// same row in the reference engine (`None` if it could not be run).
    pub reference_fallen_drop: Option<usize>,
    /// Largest rock-back (rad) of a block once past [`FALLEN_TILT`]: its
    /// largest tilt so far less its tilt now, over every look. A block
    /// that strikes its neighbour rebounds (Table 1's e1 reverses the
    /// striker, the paper's reversed blocks), by a degree or two.
    pub fallen_rock_back: f64,
    /// The same, only for blocks whose rock-back took them back below
    /// [`FALLEN_TILT`] (0 if none did): how far a block that stood up
    /// again had come back from its largest tilt.
    pub stood_up_rock_back: f64,
    /// For a Rapier run whose fallen count dropped: the reference engine's
    /// [`Observation::fallen_rock_back`] on the same row (`None` if it could
    /// not be run).
    pub reference_rock_back: Option<f64>,
    /// Blocks (1-based) that came back below [`FALLEN_TILT`] after passing
    /// it, in the order they first did.
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
    last_fallen: Option<usize>,
    /// Largest tilt (rad, absolute) of every block so far.
    peak: Vec<f64>,
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
            last_fallen: None,
            peak: Vec::new(),
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
        let fallen = blocks.iter().filter(|b| b[2].abs() > FALLEN_TILT).count();
        self.peak.resize(blocks.len(), 0.0);
        for (k, (b, peak)) in blocks.iter().zip(&mut self.peak).enumerate() {
            let tilt = b[2].abs();
            *peak = peak.max(tilt);
            if *peak > FALLEN_TILT {
                let back = *peak - tilt;
                self.seen.fallen_rock_back = self.seen.fallen_rock_back.max(back);
                if tilt <= FALLEN_TILT {
                    self.seen.stood_up_rock_back = self.seen.stood_up_rock_back.max(back);
                    if !self.seen.stood_up.contains(&(k + 1)) {
                        self.seen.stood_up.push(k + 1);
                    }
                }
            }
        }
        if let Some(last) = self.last_fallen {
            let drop = last.saturating_sub(fallen);
            if drop > 0 && self.seen.dropped.is_empty() {
                self.seen.dropped = self.moments();
            }
            self.seen.fallen_drop = self.seen.fallen_drop.max(drop);
        }
        self.last_fallen = Some(fallen);
        self.seen.fallen = fallen;
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
