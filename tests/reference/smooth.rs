//! The smooth phase of the reference engine against independent solutions.

use crate::natural_speeds;
use topple::domino::{Preset, RowSpec};
use topple::reference::{run, Settings};

/// θ(t) of a block rotating about its front bottom edge without slipping,
/// integrated here with a small fixed-step RK4:
/// I_A θ̈ = m g r sin(θ − φ₀) with r = ½√(h² + d²), tan φ₀ = d/h (docs/theory.md, τ_k).
fn pivot_theta(h: f64, d: f64, g: f64, w0: f64, t_end: f64) -> (f64, f64) {
    let r = 0.5 * (h * h + d * d).sqrt();
    let phi0 = (d / h).atan();
    let ia = (h * h + d * d) / 3.0;
    let f = |th: f64| g * r * (th - phi0).sin() / ia;
    let (mut th, mut w) = (0.0f64, w0);
    let n = 200_000;
    let dt = t_end / n as f64;
    for _ in 0..n {
        let k1 = (w, f(th));
        let k2 = (w + 0.5 * dt * k1.1, f(th + 0.5 * dt * k1.0));
        let k3 = (w + 0.5 * dt * k2.1, f(th + 0.5 * dt * k2.0));
        let k4 = (w + dt * k3.1, f(th + dt * k3.0));
        th += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        w += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
    }
    (th, w)
}

#[test]
fn first_block_rotates_about_its_edge_like_a_rigid_pendulum() {
    let p = Preset::T.params().ideal();
    let row = RowSpec::new(p, 0.5 * p.block.height, 3, 1.0);
    for (settings, tol) in [
        (Settings::accurate(1e-9), 1e-6),
        (Settings::default(), 1e-5),
    ] {
        let t_end = 0.03;
        let s = Settings {
            t_max: Some(t_end),
            series_blocks: vec![1],
            ..settings
        };
        let out = run(&row, &s).unwrap();
        let ser = &out.report.series[0];
        let t = *ser.time.last().unwrap();
        assert!((t - t_end).abs() < 1e-12);
        let (th, w) = pivot_theta(
            p.block.height,
            p.block.thickness,
            p.gravity,
            row.push / p.time_scale(),
            t,
        );
        let th_e = *ser.theta.last().unwrap();
        let w_e = *ser.theta_dot.last().unwrap();
        assert!((th_e - th).abs() < tol, "θ {th_e} vs {th}");
        assert!((w_e - w).abs() < 10.0 * tol / t_end, "θ̇ {w_e} vs {w}");
        // energy: nothing dissipated while the pivot sticks
        let e = out.report.energy.unwrap();
        assert!(e.residual.abs() < 1e-6 * e.initial, "{e:?}");
    }
}

/// The time the first block's front top corner B closes on the back face of
/// the second, which the engine takes as the instant its penetration
/// passes the gap tolerance ε = 10⁻⁶ h (`Settings::gap_tolerance`):
/// h sin θ = s + ε (rotation about the front bottom edge, from
/// [`pivot_theta`]'s equation with RK4 at 10⁻⁶ s, the crossing
/// interpolated within the last step), against the engine's first hit:
/// the event location (docs/reference-performance.md) must land on it to
/// within the integration error, far below one time step (10⁻⁴ s).
#[test]
fn the_first_hit_is_located_at_the_pendulum_crossing() {
    let p = Preset::T.params().ideal();
    let (h, d, g) = (p.block.height, p.block.thickness, p.gravity);
    let row = RowSpec::new(p, 0.3 * h, 3, 1.0);
    let target = (0.3f64 + Settings::default().gap_tolerance).asin();
    let r = 0.5 * (h * h + d * d).sqrt();
    let phi0 = (d / h).atan();
    let ia = (h * h + d * d) / 3.0;
    let f = |th: f64| g * r * (th - phi0).sin() / ia;
    let (mut th, mut w, mut t) = (0.0f64, row.push / p.time_scale(), 0.0f64);
    let dt = 1e-6;
    let crossing = loop {
        let k1 = (w, f(th));
        let k2 = (w + 0.5 * dt * k1.1, f(th + 0.5 * dt * k1.0));
        let k3 = (w + 0.5 * dt * k2.1, f(th + 0.5 * dt * k2.0));
        let k4 = (w + dt * k3.1, f(th + dt * k3.0));
        let th1 = th + dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        w += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        if th1 >= target {
            break t + dt * (target - th) / (th1 - th);
        }
        (th, t) = (th1, t + dt);
    };
    for (settings, tol) in [
        (Settings::accurate(1e-10), 1e-8),
        (Settings::default(), 1e-6),
    ] {
        let out = run(
            &row,
            &Settings {
                t_max: Some(1.2 * crossing),
                ..settings
            },
        )
        .unwrap();
        let hit = out.report.hit_times[1];
        assert!(
            (hit - crossing).abs() < tol,
            "hit {hit} s, crossing {crossing} s"
        );
    }
}

/// The smooth phase at its defaults (the paper's improved Euler at Δt =
/// 10⁻⁴ s, events located to 10⁻¹⁰ s, the derivative of a step after a
/// step without an event taken from that step's end forces, a contact
/// closing located on the positions alone; docs/reference-performance.md,
/// "Round ten") against the same rows with the smooth phase converged (Δt =
/// 2.5·10⁻⁵ s, events to 10⁻¹² s): v̂_na within the 0.1 % the defaults are
/// held to, on Table 1 rows whose blocks slide, stick and chatter (every
/// kind of event). Measured (30 blocks): T s/h 0.45 1.581244 vs 1.581245,
/// P s/h 0.3 1.580583 vs 1.580610.
#[test]
fn default_smooth_phase_against_a_converged_one() {
    let converged = Settings {
        integrator: topple::reference::Integrator::Paper { dt: 2.5e-5 },
        event_time_tolerance: 1e-12,
        ..Settings::default()
    };
    for (preset, sh) in [(Preset::T, 0.45), (Preset::P, 0.3)] {
        let p = preset.params();
        let row = RowSpec::new(p, sh * p.block.height, 30, 1.0);
        let (a, b, fallbacks) = natural_speeds(&row, &Settings::default(), &converged);
        println!("{preset:?} s/h {sh}: default {a:.6}, converged {b:.6}");
        assert!(
            (a - b).abs() < 1e-3 * b,
            "{preset:?} s/h {sh}: default {a} vs converged {b}"
        );
        assert_eq!(fallbacks, 0);
    }
}
