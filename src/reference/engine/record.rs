//! What a run records: the first hit of every block, blocks turning back,
//! θ and θ̇ series, snapshots, and the final report.

use std::time::Instant;

use super::super::snapshot::Snapshot;
use super::{Engine, RunResult};
use crate::domino::ChainReport;

impl Engine {
    /// Records the first time a pair contact (block i on block i+1) closed.
    pub(super) fn record_hits(&mut self) {
        let lambda = self.rc.p.lambda_points;
        let view = self.view();
        let mut found: Vec<usize> = Vec::new();
        let first = self.lo.saturating_sub(1);
        for i in first..self.hi.min(self.row.n - 1) {
            if self.hit[i + 1].is_some() {
                continue;
            }
            for slot in [lambda + 1, lambda + 2] {
                if let Some(g) = self.rc.geom(&view, i, slot)
                    && g.valid
                    && g.gap <= self.eps_gap
                {
                    found.push(i + 1);
                }
            }
        }
        for j in found {
            self.hit[j] = Some(self.t);
        }
    }

    pub(super) fn record(&mut self) {
        let tbar = self.rc.p.time_scale();
        for i in self.lo..self.hi {
            let (_, v) = self.state(i);
            if v[2] * tbar > 0.02 {
                self.reversed[i] = true;
            }
        }
        if !self.series.is_empty() && self.t >= self.next_sample {
            self.next_sample = self.t + self.s.series_interval;
            for k in 0..self.series.len() {
                let b = self.series[k].block;
                if b == 0 || b > self.row.n {
                    continue;
                }
                let (q, v) = self.state(b - 1);
                let s = &mut self.series[k];
                s.time.push(self.t);
                s.theta.push(-q[2]);
                s.theta_dot.push(-v[2]);
            }
        }
        while self.next_snapshot < self.s.snapshot_times.len()
            && self.t >= self.s.snapshot_times[self.next_snapshot]
        {
            self.next_snapshot += 1;
            let blocks = (0..self.row.n).map(|i| self.state(i).0).collect();
            self.snapshots.push(Snapshot {
                time: self.t,
                blocks,
            });
        }
    }

    /// The run's report, from what was recorded; `start` is when the run
    /// began, `stopped_early` whether it hit its wall-clock limit.
    pub(super) fn finish(mut self, start: Instant, stopped_early: bool) -> RunResult {
        self.sync_out();
        let row = self.row;
        let hits: Vec<f64> = self.hit.iter().map_while(|h| *h).collect();
        let mut report = ChainReport::new("reference", &row, hits);
        let (k, u) = self.energies();
        self.energy.kinetic = k;
        self.energy.potential = u;
        let en = &mut self.energy;
        en.residual = en.initial
            - (en.kinetic + en.potential + en.impacts + en.friction + en.projection + en.frozen);
        report.energy = Some(self.energy);
        report.max_penetration = Some(self.max_penetration);
        report.impacts = self.impacts;
        report.stopped_early = stopped_early;
        report.impact_fallbacks = self.impact_fallbacks;
        report.held_impacts = self.held_impacts;
        report.reversed_blocks = (0..row.n)
            .filter(|&i| self.reversed[i])
            .map(|i| i + 1)
            .collect();
        report.simulated_time = self.t;
        report.run_time = start.elapsed().as_secs_f64();
        report.series = std::mem::take(&mut self.series);
        RunResult {
            report,
            snapshots: self.snapshots,
            steps: self.steps,
            evaluations: self.evaluations,
        }
    }
}
