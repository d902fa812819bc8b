//! The no-slip ground ([`Ground::NoSlip`], the assumption of the cooperative
//! model): in the LZB resolver (μ = ∞ at a contact) against the rigid pivot in
//! closed form, and in the reference engine against the independent
//! cooperative-model oracle (tests/common/cooperative.rs).

use crate::common::cooperative::cooperative_speed;
use crate::natural_speeds;
use topple::domino::{Ground, Preset, RowSpec};
use topple::impact::{resolve, Body, Contact, ContactMaterial, ImpactSettings};
use topple::reference::{run, Settings};

/// A block (h × d, mass m) standing on two ground contacts (heel and front
/// edge, e = 0) struck horizontally at height y by a point mass M moving at
/// v (e = 0, no friction between them). Returns the outcome's velocities:
/// (block vx, vy, ω), ball vx.
fn struck_block(ground: ContactMaterial) -> ([f64; 3], f64, f64) {
    let (h, d, m, big_m, v, y) = (0.08, 0.0096, 0.02, 0.01, 1.0, 0.07);
    let inertia = m * (h * h + d * d) / 12.0;
    let block = Body::new(m, inertia).with_position([0.0, 0.5 * h]);
    let ball = Body::new(big_m, 1e-9)
        .with_position([-0.5 * d, y])
        .with_velocity([v, 0.0]);
    let ground = ground.with_restitution(0.0);
    let contacts = [
        Contact::new([None, Some(0)], [-0.5 * d, 0.0], [0.0, 1.0], ground),
        Contact::new([None, Some(0)], [0.5 * d, 0.0], [0.0, 1.0], ground),
        Contact::new(
            [Some(1), Some(0)],
            [-0.5 * d, y],
            [1.0, 0.0],
            ContactMaterial::hertz(2.3e8).with_restitution(0.0),
        ),
    ];
    let out = resolve(&[block, ball], &contacts, &ImpactSettings::default()).unwrap();
    assert!(out.kinetic_energy_after <= out.kinetic_energy_before * (1.0 + 1e-12));
    let b = out.bodies[0];
    // x velocity of the front edge (d/2, −h/2 from the centre)
    let foot = b.velocity[0] - b.angular_velocity * (-0.5 * h);
    (
        [b.velocity[0], b.velocity[1], b.angular_velocity],
        out.bodies[1].velocity[0],
        foot,
    )
}

/// With μ = ∞ at the ground the front edge is a pivot: angular momentum about
/// it is conserved, M v y = (M y² + I_A) Ω with I_A = m (h² + d²)/3, and the
/// ball leaves with the struck point's speed Ω y (plastic). Coulomb friction
/// 0.1 cannot hold the foot: it slides.
#[test]
fn no_slip_contact_in_an_impact_is_a_pivot() {
    let (h, d, m, big_m, v, y) = (0.08, 0.0096, 0.02, 0.01, 1.0, 0.07);
    let i_a = m * (h * h + d * d) / 3.0;
    let omega = big_m * v * y / (big_m * y * y + i_a);
    let (b, ball, foot) = struck_block(ContactMaterial::hertz(6.9e8).no_slip());
    assert!(
        (-b[2] - omega).abs() < 1e-3 * omega,
        "ω {} vs pivot {omega}",
        -b[2]
    );
    // Not exactly 0: an e = 0 contact whose compression has ended carries no
    // force (so no friction) until it approaches again, which the resolver
    // lands on at its switching threshold (10⁻⁹ of the approach speed per
    // step); measured 2.5·10⁻⁸ v.
    assert!(foot.abs() < 1e-6 * v, "foot slides at {foot} m/s");
    assert!(
        (ball - omega * y).abs() < 1e-3 * v,
        "ball {ball} vs {}",
        omega * y
    );
    let (_, _, slid) = struck_block(ContactMaterial::hertz(6.9e8).with_friction(0.1, 0.1));
    assert!(slid.abs() > 1e-3 * v, "Coulomb 0.1: foot {slid} m/s");
}

/// The steady wave of the ideal Domino T row on a no-slip ground against the
/// cooperative model, s/h 0.1 … 0.6: within 1 %.
///
/// The steady wave is the mean of v̂_i over the last ten blocks but the
/// last. The paper's v̂_na (mean over blocks 7 …) of a short row is not the
/// steady speed at small spacing: the leaning train builds up over tens of
/// blocks and v̂_i rises towards the natural speed all along (s/h 0.1: v̂_i
/// 0.6 at block 5, 2.05 at 25, 2.245 at 50; v̂_na of 80 blocks 2.046 against
/// a steady 2.250). So the test also checks that v̂_i has stopped rising
/// where it is measured.
///
/// One test per spacing (s/h, blocks), so that libtest runs them on all
/// cores; each checks the same as the others.
mod no_slip_ideal_row_runs_at_the_cooperative_speed {
    #[test]
    fn sh_0_1() {
        super::no_slip_ideal_row_at(0.1, 70);
    }
    #[test]
    fn sh_0_2() {
        super::no_slip_ideal_row_at(0.2, 50);
    }
    #[test]
    fn sh_0_3() {
        super::no_slip_ideal_row_at(0.3, 40);
    }
    #[test]
    fn sh_0_4() {
        super::no_slip_ideal_row_at(0.4, 30);
    }
    #[test]
    fn sh_0_5() {
        super::no_slip_ideal_row_at(0.5, 30);
    }
    #[test]
    fn sh_0_6() {
        super::no_slip_ideal_row_at(0.6, 30);
    }
}

/// An ideal Domino T row of `n` blocks at spacing `sh`·h on a no-slip
/// ground: the steady v̂_i over the tail within 1 % of the cooperative model,
/// and no longer rising there (see above).
fn no_slip_ideal_row_at(sh: f64, n: usize) {
    let mut p = Preset::T.params().ideal();
    p.ground = Ground::NoSlip;
    let (h, d) = (p.block.height, p.block.thickness);
    let row = RowSpec::new(p, sh * h, n, 1.0);
    // The model against the theory: the freeze tolerance converged
    // (10⁻⁴). The default 10⁻² freezes the far end of the slowly
    // settling leaning train, which pushes the front a little less
    // (−0.2 % at s/h 0.6; `default_freeze_is_within_half_a_percent`).
    let converged = Settings {
        freeze_tolerance: 1e-4,
        ..Settings::default()
    };
    let r = run(&row, &converged).unwrap().report;
    assert_eq!(r.hit_times.len(), n, "s/h {sh}: the wave reaches the end");
    let tail = &r.speeds[n - 12..n - 2];
    let steady = tail.iter().sum::<f64>() / tail.len() as f64;
    let oracle = cooperative_speed(h, d, sh * h, 0.0);
    let rising = tail[tail.len() - 1] - tail[0];
    println!(
        "s/h {sh}: steady {steady:.5}, cooperative {oracle:.5}, rise over the tail {rising:.1e}, v_na {:?}",
        r.natural_speed
    );
    assert!(
        rising.abs() < 2e-3 * oracle,
        "s/h {sh}: v̂_i still changes by {rising} over the last blocks"
    );
    assert!(
        (steady - oracle).abs() < 0.01 * oracle,
        "s/h {sh}: steady {steady} vs cooperative {oracle}"
    );
}

/// The defaults (adaptive impulse stepping at 10⁻⁴, freeze tolerance 10⁻²)
/// against a converged run of the same model (the paper's fixed impulse step
/// ΔP = 10⁻⁴ P₀, freeze tolerance 10⁻⁴) on ideal Domino T rows, Coulomb and
/// no-slip ground: v̂_na within 0.5 %.
///
/// One test per ground and spacing, so that libtest runs them on all cores.
mod default_freeze_is_within_half_a_percent {
    use topple::domino::Ground;
    #[test]
    fn coulomb_sh_0_3() {
        super::default_freeze_against_converged(Ground::Coulomb, 0.3);
    }
    #[test]
    fn coulomb_sh_0_6() {
        super::default_freeze_against_converged(Ground::Coulomb, 0.6);
    }
    #[test]
    fn no_slip_sh_0_3() {
        super::default_freeze_against_converged(Ground::NoSlip, 0.3);
    }
    #[test]
    fn no_slip_sh_0_6() {
        super::default_freeze_against_converged(Ground::NoSlip, 0.6);
    }
}

/// v̂_na of a 30-block ideal Domino T row at spacing `sh`·h on `ground`: the
/// defaults within 0.5 % of the converged run.
fn default_freeze_against_converged(ground: Ground, sh: f64) {
    // every approach down to round-off resolved as an impact (the default
    // approach tolerance stops those slower than 10⁻⁴ √(gh) by projection)
    let converged = Settings {
        freeze_tolerance: 1e-4,
        approach_tolerance: 1e-6,
        ..Settings::paper_impacts()
    };
    let mut p = Preset::T.params().ideal();
    p.ground = ground;
    let row = RowSpec::new(p, sh * p.block.height, 30, 1.0);
    let (a, b, _) = natural_speeds(&row, &Settings::default(), &converged);
    println!("{ground:?} s/h {sh}: default {a:.5}, converged {b:.5}");
    assert!(
        (a - b).abs() < 5e-3 * b,
        "{ground:?} s/h {sh}: default {a} vs converged {b}"
    );
}
