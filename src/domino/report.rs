//! The engine-independent report of `topple chain` (its `--json` output).

use serde::{Deserialize, Serialize};

use super::{RowSpec, Spread, WaveMeasures};

/// Energy bookkeeping of a run (J). `residual` is
/// initial − (kinetic + potential + every dissipated term), the part not
/// accounted for: time-integration error and round-off.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergyReport {
    /// Kinetic + potential energy at the start (potential from the ground).
    pub initial: f64,
    /// Kinetic energy at the end.
    pub kinetic: f64,
    /// Potential energy m g y at the end.
    pub potential: f64,
    /// Lost in impacts (kinetic energy before − after, summed).
    pub impacts: f64,
    /// Dissipated by contact forces in the smooth phase (sliding friction).
    pub friction: f64,
    /// Removed when contacts are made exactly persistent (inelastic
    /// micro-impulses of contacts closing slower than the velocity tolerance,
    /// and the constraint projections).
    pub projection: f64,
    /// Kinetic energy removed when blocks at rest are frozen.
    pub frozen: f64,
    /// What is not accounted for.
    pub residual: f64,
}

/// θ and θ̇ of one block over time (paper Fig. 7).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BlockSeries {
    /// Block number, 1-based.
    pub block: usize,
    /// Time (s).
    pub time: Vec<f64>,
    /// Paper angle θ (rad, clockwise positive).
    pub theta: Vec<f64>,
    /// θ̇ (rad/s, clockwise positive).
    pub theta_dot: Vec<f64>,
}

/// What `topple chain --json` prints; any engine can fill it.
///
/// ```
/// use topple::domino::{ChainReport, Preset, RowSpec};
/// let p = Preset::T.params();
/// let row = RowSpec::new(p, 0.02, 10, 1.0);
/// let r = ChainReport::new("reference", &row, vec![0.0, 0.1, 0.2]);
/// assert_eq!(r.speeds.len(), 2);
/// assert!(r.natural_speed.is_none()); // the wave never got past block 7
/// let json = serde_json::to_value(&r).unwrap();
/// assert!(json.get("hit_times").is_some() && json.get("engine").is_some());
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChainReport {
    /// Which engine produced it ("reference", …).
    pub engine: String,
    /// The row simulated.
    pub row: RowSpec,
    /// v̂_na, the mean of v̂_i over blocks 7, 8, … (`null` if the wave stopped
    /// earlier).
    pub natural_speed: Option<f64>,
    /// Spread of the v̂_i averaged in `natural_speed`.
    pub natural_speed_spread: Option<Spread>,
    /// v̂_i (Eq. 33) for i = 1.. (block i hitting block i+1). Infinite (JSON
    /// `null`) where two blocks were first hit at the same time, which
    /// happens in Rapier runs when blocks fall out of order.
    #[serde(deserialize_with = "super::measures::nullable::numbers")]
    pub speeds: Vec<f64>,
    /// t_i (s).
    #[serde(deserialize_with = "super::measures::nullable::numbers")]
    pub intervals: Vec<f64>,
    /// Time (s) block i was first hit, i = 1.. (block 1: 0); the blocks never
    /// reached are left out.
    pub hit_times: Vec<f64>,
    /// Energy bookkeeping, if the engine keeps it.
    pub energy: Option<EnergyReport>,
    /// Largest penetration seen at any contact, in m, if the engine tracks it.
    pub max_penetration: Option<f64>,
    /// Number of impacts resolved.
    pub impacts: usize,
    /// Impacts the LZB resolver could not finish within its step limit even
    /// with e = 0 contacts held, resolved as plastic impacts instead (should
    /// be 0 or rare).
    pub impact_fallbacks: usize,
    /// Impacts the paper's e = 0 law could not finish within the step limit,
    /// solved again with e = 0 contacts held closed
    /// ([`crate::impact::ImpactSettings::e0_hold`]).
    #[serde(default)]
    pub held_impacts: usize,
    /// Blocks that rotated anticlockwise (θ̇ < 0) at some time, 1-based.
    pub reversed_blocks: Vec<usize>,
    /// The run hit its wall-clock limit before the wave finished.
    pub stopped_early: bool,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// Wall-clock run time (s).
    pub run_time: f64,
    /// Time series of chosen blocks.
    pub series: Vec<BlockSeries>,
}

impl ChainReport {
    /// A report with the measures of `hit_times`; the other fields empty.
    pub fn new(engine: &str, row: &RowSpec, hit_times: Vec<f64>) -> ChainReport {
        let m = WaveMeasures::from_hit_times(row, &hit_times);
        ChainReport {
            engine: engine.to_string(),
            row: *row,
            natural_speed: m.natural_speed.map(|s| s.mean),
            natural_speed_spread: m.natural_speed,
            speeds: m.speeds,
            intervals: m.intervals,
            hit_times,
            energy: None,
            max_penetration: None,
            impacts: 0,
            impact_fallbacks: 0,
            held_impacts: 0,
            reversed_blocks: Vec::new(),
            stopped_early: false,
            simulated_time: 0.0,
            run_time: 0.0,
            series: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domino::Preset;

    /// Saved reports are matched to rows by equality (`topple bench`), so a
    /// report must come back from JSON bit for bit, infinite speeds as NaN.
    #[test]
    fn a_report_round_trips_through_json() {
        let p = Preset::X.params();
        let row = RowSpec::new(p, 0.18 * p.block.height, 12, 1.0);
        // blocks 3 and 4 hit at the same time: t_3 = 0, v̂_3 infinite
        let hits = vec![0.0, 0.1, 0.2, 0.2, 0.30000000000000004, 0.4];
        let report = ChainReport::new("rapier", &row, hits);
        assert!(report.speeds.iter().any(|v| v.is_infinite()));
        let text = serde_json::to_string(&report).unwrap();
        let back: ChainReport = serde_json::from_str(&text).unwrap();
        assert_eq!(back.row, row);
        assert_eq!(back.hit_times, report.hit_times);
        for (a, b) in back.speeds.iter().zip(&report.speeds) {
            assert!(a == b || (a.is_nan() && b.is_infinite()), "{a} vs {b}");
        }
    }
}
