//! A box dropped flat and one dropped on an edge, in Rapier with topple:
//! the post-impact state against the LZB resolver fed, here, the same contact
//! built from the box geometry and free fall (λ points across the base for the
//! flat drop, the lowest corner for the edge drop); energy is never created at
//! an impact. Native Rapier's rebound is printed for the record. Both sides
//! step the impact with the paper's fixed impulse step, so that they compare
//! the same integration of the same law.

use topple::impact::{resolve, Body, Contact, ContactMaterial, ImpactSettings};
use topple::rapier::f64::build;
use topple::rapier::scene::{ImpactResponse, Scene};

const W: f64 = 0.10; // m
const H: f64 = 0.05; // m
const G: f64 = 9.81; // m/s²
const K: f64 = 1e8;
const E: f64 = 0.5;
const MU: f64 = 0.3;
const MU_S: f64 = 0.35;

fn scene(y: f64, angle: f64) -> Scene {
    toml::from_str(&format!(
        "duration = 0.5\n[solver]\nmax_work = \"none\"\ndt = 1e-4\nlength_unit = 0.05\nimpulse_step = 1e-4\n\
         [[materials]]\nname = \"wood\"\nstiffness = {K}\nrestitution = {E}\nfriction = {MU}\n\
         stick_friction = {MU_S}\n[ground]\ny = 0.0\nmaterial = \"wood\"\n\
         [[bodies]]\nshape = \"box\"\nsize = [{W}, {H}]\nposition = [0.0, {y}]\nangle = {angle}\n\
         mass = 1.0\nmaterial = \"wood\"\n"
    ))
    .unwrap()
}

fn material() -> ContactMaterial {
    ContactMaterial::hertz(K)
        .with_restitution(E)
        .with_friction(MU, MU_S)
}

fn inertia() -> f64 {
    (W * W + H * H) / 12.0 // m = 1 kg
}

/// Runs until the first impact and returns (velocity, ω) just after it, the
/// highest centre height after it, and the largest relative energy gain of any
/// impact.
fn run(scene: &Scene, engine: ImpactResponse) -> ([f64; 2], f64, f64, f64) {
    let mut sw = build(scene, engine).unwrap();
    let h = sw.bodies[0].1;
    let mut after: Option<([f64; 2], f64)> = None;
    let mut prev_vy = 0.0;
    let mut apex = f64::NEG_INFINITY;
    let mut gain: f64 = 0.0;
    for _ in 0..3000 {
        let reports = sw.step().to_vec();
        for r in &reports {
            gain = gain
                .max((r.kinetic_energy_after - r.kinetic_energy_before) / r.kinetic_energy_before);
        }
        let rb = &sw.world.bodies[h];
        let v = [rb.linvel().x, rb.linvel().y];
        // first step that reverses the fall (topple: the impact; native: Rapier's bounce)
        if after.is_none() && prev_vy < -0.5 && v[1] > prev_vy + 0.5 {
            after = Some((v, rb.angvel()));
        }
        if after.is_some() {
            apex = apex.max(rb.center_of_mass().y);
            if v[1] < 0.0 && apex > 0.0 {
                break;
            }
        }
        prev_vy = v[1];
    }
    let (v, w) = after.expect("the box never bounced");
    (v, w, apex, gain)
}

#[test]
fn box_dropped_flat_rebounds_as_the_resolver_says() {
    let drop = 0.2; // m, base above ground
    let y0 = drop + 0.5 * H;
    let v_in = -(2.0 * G * drop).sqrt();
    let body = Body::new(1.0, inertia())
        .with_position([0.0, 0.5 * H])
        .with_velocity([0.0, v_in]);
    let contacts: Vec<Contact> = (0..9)
        .map(|p| {
            let x = -0.5 * W + W * p as f64 / 8.0; // docs/model.md §5: edge to edge
            Contact::new([None, Some(0)], [x, 0.0], [0.0, 1.0], material())
        })
        .collect();
    let out = resolve(&[body], &contacts, &ImpactSettings::default()).unwrap();
    let v_out = out.bodies[0].velocity[1];
    let apex_expected = 0.5 * H + v_out * v_out / (2.0 * G);

    let (v, w, apex, gain) = run(&scene(y0, 0.0), ImpactResponse::Topple);
    let (_, _, apex_native, _) = run(&scene(y0, 0.0), ImpactResponse::Native);
    eprintln!(
        "flat drop: resolver v' = {v_out:.5} m/s, apex {apex_expected:.5} m; \
         topple v' = {:.5}, w' = {w:.2e}, apex {apex:.5} m; native apex {apex_native:.5} m",
        v[1]
    );
    assert!(gain <= 1e-12, "an impact created energy: {gain:e}");
    assert!(
        (v[1] - v_out).abs() < 0.01 * v_out.abs(),
        "rebound speed {} vs {v_out}",
        v[1]
    );
    assert!((apex - apex_expected).abs() < 0.02 * (apex_expected - 0.5 * H));
    assert!(w.abs() < 1e-3, "a flat drop must not spin: {w}");
}

#[test]
fn box_dropped_on_edge_spins_as_the_resolver_says() {
    let theta = std::f64::consts::FRAC_PI_6;
    let y0 = 0.3;
    let (s, c) = theta.sin_cos();
    // lowest corner (−W/2, −H/2) rotated by θ
    let corner = [-0.5 * W * c + 0.5 * H * s, -0.5 * W * s - 0.5 * H * c];
    let fall = y0 + corner[1];
    let v_in = -(2.0 * G * fall).sqrt();
    let body = Body::new(1.0, inertia())
        .with_position([0.0, -corner[1]])
        .with_velocity([0.0, v_in]);
    let contact = Contact::new([None, Some(0)], [corner[0], 0.0], [0.0, 1.0], material());
    let out = resolve(&[body], &[contact], &ImpactSettings::default()).unwrap();
    let expect = out.bodies[0];

    let (v, w, _, gain) = run(&scene(y0, theta), ImpactResponse::Topple);
    let (vn, wn, _, _) = run(&scene(y0, theta), ImpactResponse::Native);
    eprintln!(
        "edge drop: resolver v' = {:.5?}, w' = {:.4}; topple v' = {v:.5?}, w' = {w:.4}; \
         native v' = {vn:.5?}, w' = {wn:.4}",
        expect.velocity, expect.angular_velocity
    );
    assert!(gain <= 1e-12, "an impact created energy: {gain:e}");
    let tol = 0.01 * v_in.abs();
    assert!((v[0] - expect.velocity[0]).abs() < tol && (v[1] - expect.velocity[1]).abs() < tol);
    let r = 0.5 * W.hypot(H);
    assert!(
        (w - expect.angular_velocity).abs() * r < tol,
        "spin {w} vs {}",
        expect.angular_velocity
    );
}
