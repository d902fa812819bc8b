//! Time of impact: the first instant a candidate's gap closes along the
//! bodies' straight paths.

use crate::coupling::ToppleSettings;

use super::{closed_tolerance, ImpactPass, World, TOI_ITERATIONS};

impl ImpactPass {
    /// The segment start of a candidate: the later of its bodies' path starts.
    pub(super) fn segment_start(&mut self, world: &World, k: usize) -> f64 {
        let mut t0: f64 = 0.0;
        for c in self.candidates[k].colliders {
            if let Some((h, rb)) = world
                .colliders
                .get(c)
                .and_then(|co| co.parent())
                .and_then(|h| world.bodies.get(h).map(|rb| (h, rb)))
                && rb.is_dynamic()
            {
                t0 = t0.max(self.motion.path(h, rb).t0);
            }
        }
        t0
    }

    /// The first instant (s) a candidate's gap closes (≤ the closed
    /// tolerance) on its segment, if it is closed at the end of the step.
    /// The gap is sampled at four points to bracket its first closing, then
    /// the bracket is narrowed by regula falsi (Illinois) to within the
    /// tolerance or 10⁻⁹ of the step.
    pub(super) fn time_of_impact(
        &mut self,
        world: &World,
        settings: &ToppleSettings,
        k: usize,
    ) -> f64 {
        let dt = self.motion.dt;
        let t0 = self.segment_start(world, k);
        let tol = closed_tolerance(settings);
        let far = 1e3 * world.prediction.max(tol) + world.length_unit;
        let search = Search { k, tol, far };
        let end = self.gap_at(world, &search, dt);
        if end > tol {
            return f64::INFINITY;
        }
        match self.bracket(world, &search, t0, end) {
            Ok(closed) => closed,
            Err(bracket) => self.narrow(world, &search, bracket),
        }
    }

    /// The candidate's gap (m) at time `t`, `far` beyond the search's reach.
    fn gap_at(&mut self, world: &World, search: &Search, t: f64) -> f64 {
        self.gap(world, search.k, t, search.far)
            .unwrap_or(search.far)
    }

    /// Samples the gap at the segment start and at a quarter, half and
    /// three quarters of the rest of the step: `Ok(t0)` if it is closed at
    /// the start, else the bracket `(a, g(a), b, g(b))` of the first
    /// closing (the end of the step closes with gap `end` (m), the caller
    /// checked).
    fn bracket(
        &mut self,
        world: &World,
        search: &Search,
        t0: f64,
        end: f64,
    ) -> Result<f64, [f64; 4]> {
        let dt = self.motion.dt;
        let (mut a, mut ga) = (t0, self.gap_at(world, search, t0));
        if ga <= search.tol {
            return Ok(t0);
        }
        let mut b = dt;
        let mut gb = end;
        for j in 1..4 {
            let t = t0 + (dt - t0) * j as f64 / 4.0;
            let g = self.gap_at(world, search, t);
            if g <= search.tol {
                (b, gb) = (t, g);
                break;
            }
            (a, ga) = (t, g);
        }
        Err([a, ga, b, gb])
    }

    /// Narrows a bracket of the first closing by regula falsi (Illinois) on
    /// f = g − tol/2, where any t with |f| ≤ tol/2 is closed, to within the
    /// tolerance or 10⁻⁹ of the step; returns the closed end otherwise.
    fn narrow(&mut self, world: &World, search: &Search, [a, ga, b, gb]: [f64; 4]) -> f64 {
        let dt = self.motion.dt;
        let target = 0.5 * search.tol;
        let (mut a, mut b) = (a, b);
        let (mut fa, mut fb) = (ga - target, gb - target);
        let mut side = 0;
        for _ in 0..TOI_ITERATIONS {
            if b - a <= 1e-9 * dt {
                break;
            }
            let t = (a * fb - b * fa) / (fb - fa);
            let t = if t > a && t < b { t } else { 0.5 * (a + b) };
            let f = self.gap_at(world, search, t) - target;
            if f.abs() <= target {
                return t;
            }
            if f > 0.0 {
                (a, fa) = (t, f);
                if side == 1 {
                    fb *= 0.5;
                }
                side = 1;
            } else {
                (b, fb) = (t, f);
                if side == -1 {
                    fa *= 0.5;
                }
                side = -1;
            }
        }
        b
    }

    /// The earliest time of impact among the open candidates.
    pub(super) fn earliest(&self) -> Option<f64> {
        self.candidates
            .iter()
            .filter(|c| !c.done && c.toi.is_finite())
            .map(|c| c.toi)
            .min_by(f64::total_cmp)
    }
}

/// One time-of-impact search: the candidate, the closed tolerance (m) and
/// the gap (m) reported for a pair beyond reach.
struct Search {
    k: usize,
    tol: f64,
    far: f64,
}
