//! Trends of the reference engine's natural speed:
//! friction between blocks against the extended group model (Fig. 5), and the
//! parameter studies of Figs. 9 and 10 on Domino X. The natural speed v̂_na is
//! the mean of v̂_i over blocks 7..; its spread is the standard
//! deviation of those v̂_i. Numbers quoted are measured with the paper's
//! integration (improved Euler, Δt = 10⁻⁴ s), push 1.0.

use crate::common::cooperative::cooperative_speed;
use topple::domino::{ChainReport, Preset, RowParams, RowSpec};
use topple::reference::{run, Settings};

fn run_row(p: RowParams, spacing_ratio: f64, n: usize) -> ChainReport {
    let row = RowSpec::new(p, spacing_ratio * p.block.height, n, 1.0);
    let r = run(&row, &Settings::default()).unwrap().report;
    assert_eq!(r.hit_times.len(), n, "the wave reaches the end of the row");
    assert!(!r.stopped_early);
    r
}

fn v_na(r: &ChainReport) -> (f64, f64) {
    let s = r.natural_speed_spread.unwrap();
    (s.mean, s.std_dev)
}

/// Domino T on the ideal ground (μ2 = 0.9, e2 = 0), e1 = 0, μ1 = μ1_s = `mu1`.
fn t_with_mu1(mu1: f64, impact_friction_factor: f64) -> RowParams {
    let mut p = Preset::T.params().ideal();
    p.mu1 = mu1;
    p.mu1_stick = mu1;
    p.impact_friction_factor = impact_friction_factor;
    p
}

/// The extended group model (independent oracle) for Domino T.
fn extended(spacing_ratio: f64, mu: f64) -> f64 {
    let b = Preset::T.params().block;
    cooperative_speed(b.height, b.thickness, spacing_ratio * b.height, mu)
}

/// Domino X on the ideal ground of Figs. 9 and 10 (μ2 = 0.9, e2 = 0) with
/// μ1 = μ1_s = `mu1` and restitution `e1` between blocks.
fn x_with(mu1: f64, e1: f64) -> RowParams {
    let mut p = Preset::X.params().ideal();
    p.mu1 = mu1;
    p.mu1_stick = mu1;
    p.e1 = e1;
    p
}

/// Asserts `hi − lo` exceeds the sum of the two runs' spreads (standard
/// deviations of v̂_i over blocks 7..20) and `floor`.
fn assert_drop(what: &str, hi: (f64, f64), lo: (f64, f64), floor: f64) {
    let margin = (hi.1 + lo.1).max(floor);
    assert!(
        hi.0 - lo.0 > margin,
        "{what}: {:.4} ± {:.4} should exceed {:.4} ± {:.4} by more than {margin:.4}",
        hi.0,
        hi.1,
        lo.0,
        lo.1
    );
}

// ---------------------------------------------------------------------------
// Issue item 2 (Fig. 5, Sec. 3.2): μ1 = 0.15, e1 = 0, Domino T, ideal ground.
//
// The paper: "the extended group model can give a good prediction when domino
// spacing is not sufficiently large. For a large domino spacing, however, a
// relative large error exists". The engine does NOT reproduce this: with the
// paper's settings (impact friction 0.5 × μ1, docs/model.md §4) it reads about 5 %
// above the extended model at every spacing it runs cleanly (+6.4 %
// at s/h 0.35, +6.8 % at 0.4, +5.6 % at 0.45, +5.2 % at 0.5, +5.0 % at 0.55,
// 30 blocks; +4.8 % at 0.55 and 0.6 with 20 blocks), and the deviation shrinks
// rather than grows with s/h. What the engine does, and what these tests hold,
// is physically justified against the extended model of the independent
// oracle: the extended model has one friction coefficient for the smooth
// phase and the collisions alike, the engine uses μ1 between impacts and
// μ1/2 inside them, so its speed lies between the extended model at μ1 and at
// μ1/2; and with the impact friction factor set to 1 (one μ, as the extended
// model assumes) it lands on the extended model.
// ---------------------------------------------------------------------------

/// Paper settings (impact friction factor 0.5): ext(μ1) < v̂_na < ext(μ1/2),
/// each gap larger than 3 × the spread of v̂_na. Measured, 20 blocks:
/// s/h 0.55: 1.4553 ± 0.0103 between 1.3880 and 1.5199 (cooperative 1.6835);
/// s/h 0.60: 1.4266 ± 0.0066 between 1.3609 and 1.4930.
#[test]
fn friction_between_blocks_lies_between_the_extended_models_at_mu_and_half_mu() {
    for sh in [0.55, 0.6] {
        let r = run_row(t_with_mu1(0.15, 0.5), sh, 20);
        assert_eq!(r.impact_fallbacks, 0, "s/h {sh}");
        let (v, sd) = v_na(&r);
        let (lo, hi) = (extended(sh, 0.15), extended(sh, 0.075));
        assert!(
            v - lo > 3.0 * sd && hi - v > 3.0 * sd,
            "s/h {sh}: v_na {v:.4} ± {sd:.4} not inside ({lo:.4}, {hi:.4})"
        );
        // and below the frictionless (cooperative) model
        assert!(v < extended(sh, 0.0) - 3.0 * sd);
    }
}

/// Impact friction equal to the contact friction (factor 1, the extended
/// model's single μ): v̂_na within 2 % of the extended model (the tolerance of
/// issue item 1 for the cooperative model). Measured, 20 blocks, s/h 0.55:
/// 1.3866 ± 0.0084 vs 1.3880 (−0.1 %); 30 blocks, s/h 0.35: 1.4760 vs 1.4936
/// (−1.2 %, too slow for this test).
#[test]
fn with_full_impact_friction_the_engine_follows_the_extended_model() {
    let sh = 0.55;
    let r = run_row(t_with_mu1(0.15, 1.0), sh, 20);
    assert_eq!(r.impact_fallbacks, 0);
    let (v, _) = v_na(&r);
    let ext = extended(sh, 0.15);
    assert!(
        (v - ext).abs() < 0.02 * ext,
        "v_na {v:.4} vs extended {ext:.4}"
    );
}

// ---------------------------------------------------------------------------
// Issue item 5 (Figs. 9, 10, Sec. 3.4) on Domino X, s/h 0.52, 20 blocks. The
// paper: "the speed decreases as either of the coefficients of friction μ1
// or μ2 increases", "the speed will dramatically decrease with the increase of
// the friction between dominoes", e1 and e2 have a small influence, "but as
// the coefficient of restitution between dominoes e1 is large enough, an
// obvious increase of the natural speed can be observed", partly from "the
// rebound motion of dominoes". Each trend must exceed the sum of the two
// runs' spreads of v̂_i (a conservative margin: v̂_na is a mean of 13 v̂_i).
// s/h 0.52 is the spacing where the engine runs every value cleanly; at 0.18
// and 0.35 some runs of `topple paper` hit plastic fallbacks.
// ---------------------------------------------------------------------------

/// Fig. 9a: v̂_na falls as μ1 rises. Measured: μ1 0 → 1.6626 ± 0.0211,
/// 0.1 → 1.4844 ± 0.0130, 0.2 → 1.3406 ± 0.0081 (drops 0.178 and 0.144).
#[test]
fn speed_falls_as_friction_between_blocks_rises() {
    let v: Vec<(f64, f64)> = [0.0, 0.1, 0.2]
        .iter()
        .map(|&mu1| v_na(&run_row(x_with(mu1, 0.0), 0.52, 20)))
        .collect();
    assert_drop("mu1 0 -> 0.1", v[0], v[1], 0.1);
    assert_drop("mu1 0.1 -> 0.2", v[1], v[2], 0.1);
}

/// Fig. 10a: v̂_na falls as μ2 rises (μ1 = e1 = e2 = 0). Measured: μ2 0.3 →
/// 1.7264 ± 0.0120, μ2 0.9 → 1.6626 ± 0.0211 (drop 0.064, margin 0.033).
#[test]
fn speed_falls_as_ground_friction_rises() {
    let mut p = x_with(0.0, 0.0);
    p.mu2 = 0.3;
    p.mu2_stick = 0.3;
    let low = v_na(&run_row(p, 0.52, 20));
    let high = v_na(&run_row(x_with(0.0, 0.0), 0.52, 20));
    assert_drop("mu2 0.3 -> 0.9", low, high, 0.03);
}

/// Fig. 9b: e1 changes little while small and raises v̂_na when large, with
/// rebounds (blocks turning anticlockwise). Measured: e1 0 → 1.6626 ± 0.0211,
/// 0.4 → 1.6654 ± 0.0213 (no block turns back), 0.8 → 1.7283 ± 0.0147
/// (17 of 20 blocks turn back at some time).
#[test]
fn speed_rises_with_restitution_between_blocks_when_it_is_large() {
    let r0 = run_row(x_with(0.0, 0.0), 0.52, 20);
    let r4 = run_row(x_with(0.0, 0.4), 0.52, 20);
    let r8 = run_row(x_with(0.0, 0.8), 0.52, 20);
    let (v0, v4, v8) = (v_na(&r0), v_na(&r4), v_na(&r8));
    // small e1: a change within the spread of v̂_i
    assert!(
        (v4.0 - v0.0).abs() < v0.1.min(v4.1),
        "e1 0 -> 0.4: {v0:?} -> {v4:?}"
    );
    // large e1: a rise beyond the spreads
    assert_drop("e1 0.4 -> 0.8", v8, v4, 0.03);
    // with rebounds
    assert!(r4.reversed_blocks.is_empty(), "{:?}", r4.reversed_blocks);
    assert!(r8.reversed_blocks.len() >= 5, "{:?}", r8.reversed_blocks);
}
