//! Newton's cradles in Rapier: topple against a Hertz chain integrated here,
//! independently of the program (RK4 on m ẍ = forces of F = k δ^1.5).
//! Native Rapier's distance from the same chain is printed for the record.

use topple::rapier::scene::{run_scene, ImpactResponse, RunOptions, Scene};
use topple::rapier::Precision;

const K: f64 = 2.3e10; // N/m^1.5
const R: f64 = 0.05; // m
const M: f64 = 1.0; // kg
const V0: f64 = 1.0; // m/s, striking speed

/// The cradle of `n` balls; the impact is stepped with the paper's fixed
/// impulse step (ΔP = 10⁻⁴ P₀), the finest of the resolver's settings: the
/// test is about the LZB law matching the compliant chain, not about the
/// adaptive step's tolerance (at the default 10⁻⁴ a five-ball cradle is off
/// the chain by 2.4·10⁻³ V₀, at 10⁻⁶ by 2.2·10⁻⁴ V₀).
fn scene(n: usize) -> Scene {
    let mut s = format!(
        "duration = 0.005\ngravity = [0.0, 0.0]\n[solver]\nmax_work = \"none\"\ndt = 1e-4\nlength_unit = 0.1\nimpulse_step = 1e-4\n\
         [[materials]]\nname = \"steel\"\nstiffness = {K}\nrestitution = 1.0\n"
    );
    for i in 0..n {
        let v = if i == 0 { V0 } else { 0.0 };
        s += &format!(
            "[[bodies]]\nshape = \"ball\"\nradius = {R}\nposition = [{}, 0.0]\n\
             velocity = [{v}, 0.0]\nmass = {M}\nmaterial = \"steel\"\n",
            2.0 * R * i as f64
        );
    }
    toml::from_str(&s).unwrap()
}

/// Final velocities of a chain of touching equal balls, the first at V0:
/// classical RK4 on the compliant model, step 1e-8 s (contact time ≈ 1.6e-4 s),
/// run until no contact is loaded and none approaches.
fn hertz_chain(n: usize) -> Vec<f64> {
    let mut x: Vec<f64> = (0..n).map(|i| 2.0 * R * i as f64).collect();
    let mut v = vec![0.0; n];
    v[0] = V0;
    let acc = |x: &[f64]| {
        let mut a = vec![0.0; x.len()];
        for i in 0..x.len() - 1 {
            let overlap = x[i] + 2.0 * R - x[i + 1];
            if overlap > 0.0 {
                let f = K * overlap.powf(1.5);
                a[i] -= f / M;
                a[i + 1] += f / M;
            }
        }
        a
    };
    let h = 1e-8;
    for step in 0.. {
        let a1 = acc(&x);
        let x2: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * v[i]).collect();
        let v2: Vec<f64> = (0..n).map(|i| v[i] + 0.5 * h * a1[i]).collect();
        let a2 = acc(&x2);
        let x3: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * v2[i]).collect();
        let v3: Vec<f64> = (0..n).map(|i| v[i] + 0.5 * h * a2[i]).collect();
        let a3 = acc(&x3);
        let x4: Vec<f64> = (0..n).map(|i| x[i] + h * v3[i]).collect();
        let v4: Vec<f64> = (0..n).map(|i| v[i] + h * a3[i]).collect();
        let a4 = acc(&x4);
        for i in 0..n {
            x[i] += h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
            v[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
        }
        let done = (0..n - 1).all(|i| x[i] + 2.0 * R - x[i + 1] <= 0.0 && v[i] <= v[i + 1]);
        if step > 100 && done {
            break;
        }
        assert!(step < 10_000_000, "chain did not separate");
    }
    v
}

fn final_vx(scene: &Scene, engine: ImpactResponse) -> Vec<f64> {
    let out = run_scene(scene, engine, Precision::F64, RunOptions::default()).unwrap();
    out.bodies.iter().map(|b| b.velocity[0]).collect()
}

fn check(n: usize) {
    let chain = hertz_chain(n);
    // The chain itself conserves momentum and energy (a check on the oracle).
    let p: f64 = chain.iter().sum::<f64>() * M;
    let e: f64 = chain.iter().map(|v| 0.5 * M * v * v).sum();
    assert!((p - M * V0).abs() < 1e-9 && (e - 0.5 * M * V0 * V0).abs() < 1e-6);
    let s = scene(n);
    let topple = final_vx(&s, ImpactResponse::Topple);
    let native = final_vx(&s, ImpactResponse::Native);
    let err = |v: &[f64]| {
        v.iter()
            .zip(&chain)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / V0
    };
    eprintln!("cradle {n}: Hertz chain {chain:.5?}");
    eprintln!(
        "cradle {n}: topple        {topple:.5?}  max error {:.2e} V0",
        err(&topple)
    );
    eprintln!(
        "cradle {n}: native Rapier {native:.5?}  max error {:.2e} V0",
        err(&native)
    );
    assert!(
        err(&topple) < 1e-3,
        "topple off the Hertz chain by {:.3e} V0",
        err(&topple)
    );
}

#[test]
fn cradle_of_three_matches_hertz_chain() {
    check(3);
}

#[test]
fn cradle_of_five_matches_hertz_chain() {
    check(5);
}
