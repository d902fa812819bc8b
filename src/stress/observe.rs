//! What one run shows, measured from the block states alone (centre and
//! angle of every block), independently of the engine's own report.

use crate::impact::audit::AuditSummary;
use crate::validate::box_overlap;

/// A block counts as fallen past this tilt (rad). A block first touches the
/// next one at a tilt asin(s/h) < π/4 for every s/h the sweep draws (< 0.6);
/// past π/4 it lies on a block that itself only moves forward, so no force
/// of the row can stand it up again: the fallen count can only grow.
pub const FALLEN_TILT: f64 = std::f64::consts::FRAC_PI_4;

/// The observations of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Observation {
    /// A block state (or a report value) was NaN or infinite.
    pub non_finite: bool,
    /// Largest overlap of two neighbouring blocks, or of a block with the
    /// ground, over the block height.
    pub penetration: f64,
    /// Where the largest penetration was: "blocks i/i+1" or "block i/ground"
    /// (1-based), at which look (count from 1).
    pub penetration_at: String,
    /// Largest drop of the fallen count between two observed instants.
    pub fallen_drop: usize,
    /// Blocks fallen at the end.
    pub fallen: usize,
    /// Blocks hit by the wave.
    pub hits: usize,
    /// The run did not end within its budget (its engine's own limits or the
    /// sweep's wall-clock budget).
    pub over_budget: bool,
    /// Wall-clock time of the run (s).
    pub wall: f64,
    /// The impacts, checked independently (see [`crate::impact::audit`]).
    pub audit: AuditSummary,
    /// An error the engine returned (the run could not be done).
    pub error: Option<String>,
}

/// Tracks the states of a row of blocks of height `h`, thickness `d`
/// standing on the ground at y = 0.
#[derive(Clone, Debug)]
pub struct RowWatch {
    half: [f64; 2],
    h: f64,
    last_fallen: Option<usize>,
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
            last_fallen: None,
            looks: 0,
            seen: Observation::default(),
        }
    }

    /// Looks at the row: (x, y, angle) of every block, in row order.
    pub fn look(&mut self, blocks: &[[f64; 3]]) {
        if blocks.iter().flatten().any(|v| !v.is_finite()) {
            self.seen.non_finite = true;
            return;
        }
        self.looks += 1;
        let mut worst = (0.0, String::new());
        for (i, w) in blocks.windows(2).enumerate() {
            let a = ([w[0][0], w[0][1]], w[0][2]);
            let b = ([w[1][0], w[1][1]], w[1][2]);
            let depth = box_overlap(a, b, self.half);
            if depth > worst.0 {
                worst = (depth, format!("blocks {}/{}", i + 1, i + 2));
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
            self.seen.penetration_at = format!("{} at look {}", worst.1, self.looks);
        }
        let fallen = blocks.iter().filter(|b| b[2].abs() > FALLEN_TILT).count();
        if let Some(last) = self.last_fallen {
            self.seen.fallen_drop = self.seen.fallen_drop.max(last.saturating_sub(fallen));
        }
        self.last_fallen = Some(fallen);
        self.seen.fallen = fallen;
    }
}
