//! Checks of the theory models: known values, limits, monotonicity,
//! and derivations written here independently of `src/theory`.

use topple::theory::{min_spacing, solve, Geometry, Model, NoWave, Outcome};

fn speed(model: Model, d: f64, s: f64) -> f64 {
    solve(&model, &Geometry::new(d, s).unwrap())
        .unwrap()
        .natural_speed()
        .unwrap_or_else(|| panic!("{model:?} has no wave at d/h = {d}, s/h = {s}"))
}

/// docs/theory.md: h = 48 mm, d = 7.5 mm, λ = 16 mm, g = 9.8 m/s² gives 1.380 m/s at
/// μ = 0 and 1.023 m/s at μ = 0.2. The values are printed with 4 digits
/// (±0.0005 m/s); we allow 0.1 % (about ±0.0014 m/s and ±0.0010 m/s).
#[test]
fn known_values_of_van_leeuwen() {
    let (h, d, lambda, g) = (0.048_f64, 0.0075, 0.016, 9.8);
    let (dh, sh) = (d / h, (lambda - d) / h);
    let scale = (g * h).sqrt();
    let v0 = speed(Model::Cooperative, dh, sh) * scale;
    let v2 = speed(Model::Extended { mu: 0.2 }, dh, sh) * scale;
    assert!((v0 - 1.380).abs() <= 1e-3 * 1.380, "mu = 0: {v0} m/s");
    assert!((v2 - 1.023).abs() <= 1e-3 * 1.023, "mu = 0.2: {v2} m/s");
}

/// Extended → cooperative as μ → 0, and the difference is first order in μ.
#[test]
fn extended_tends_to_cooperative() {
    for &(d, s) in &[(0.12, 0.15), (0.12, 0.5), (0.2, 0.3), (0.08, 0.8)] {
        let v0 = speed(Model::Cooperative, d, s);
        let tiny = speed(Model::Extended { mu: 1e-9 }, d, s);
        assert!((tiny - v0).abs() <= 1e-8 * v0, "{d} {s}: {tiny} vs {v0}");
        let d3 = v0 - speed(Model::Extended { mu: 1e-3 }, d, s);
        let d4 = v0 - speed(Model::Extended { mu: 1e-4 }, d, s);
        assert!(d3 > 0.0 && d4 > 0.0);
        let ratio = d3 / d4;
        assert!((ratio - 10.0).abs() < 0.1, "{d} {s}: ratio {ratio}");
    }
}

/// θ_∞ is the fixed point of the leaning geometry h sin(θ_{k+1} − θ_k) = λ cos θ_k − d,
/// and a train started at the collision angle converges to it.
#[test]
fn rest_angle_is_fixed_point_of_leaning() {
    for &(d, s) in &[(0.12, 0.1), (0.12, 0.6), (0.25, 0.4), (0.05, 0.9)] {
        let geom = Geometry::new(d, s).unwrap();
        let theta_inf = geom.rest_angle();
        // independent statement of the leaning relation
        let lean = |t: f64| t + ((s + d) * t.cos() - d).asin();
        assert!((lean(theta_inf) - theta_inf).abs() < 1e-14);
        assert!((geom.lean_behind(theta_inf) - theta_inf).abs() < 1e-14);
        let mut t = (s).asin();
        for _ in 0..5000 {
            t = lean(t);
        }
        assert!((t - theta_inf).abs() < 1e-12, "{d} {s}: {t} vs {theta_inf}");
        let w = solve(&Model::Cooperative, &geom).unwrap();
        if let Outcome::Wave(w) = w {
            assert_eq!(w.theta_inf, theta_inf);
            assert!((w.theta_c - s.asin()).abs() < 1e-15);
        }
    }
}

/// The natural speed falls as the friction between blocks grows.
#[test]
fn speed_falls_with_friction() {
    for &s in &[0.2, 0.4, 0.6, 0.8] {
        let mut last = speed(Model::Cooperative, 0.12, s);
        for i in 1..=6 {
            let mu = 0.05 * i as f64;
            let v = speed(Model::Extended { mu }, 0.12, s);
            assert!(v < last, "extended s/h = {s}, mu = {mu}: {v} !< {last}");
            last = v;
        }
        let mut last = speed(Model::Single { mu: 0.0, e: 0.62 }, 0.12, s.max(0.4));
        for i in 1..=6 {
            let mu = 0.05 * i as f64;
            let v = speed(Model::Single { mu, e: 0.62 }, 0.12, s.max(0.4));
            assert!(v < last, "single s/h = {s}, mu = {mu}: {v} !< {last}");
            last = v;
        }
    }
}

/// Cooperative model (μ = 0) by energy conservation, written independently: the
/// train is one degree of freedom with kinetic energy ½ I K(θ) θ̇² (K = Σ c_k²) and
/// potential Σ m g y_k; the collision keeps the old train's angular momentum
/// weighted by c: ω_new = ω_old K_c/(K_c + 1). Period by composite Simpson
/// (400 intervals, error far below 10⁻⁹), so the check is at 10⁻⁹, well inside
/// the 10⁻⁶ promised.
#[test]
fn cooperative_matches_energy_derivation() {
    for &(d, s) in &[(0.12, 0.2), (0.12, 0.45), (0.2, 0.7)] {
        let lambda = s + d;
        // train angles, the squares of the velocity ratios and the centre-of-mass heights
        let train = |t0: f64| {
            let (mut t, mut c, mut k, mut y) = (t0, 1.0_f64, 0.0, 0.0);
            for _ in 0..3000 {
                k += c * c;
                // centre of mass at (−d/2, h/2) in the block, rotated forward by t
                y += 0.5 * t.cos() + 0.5 * d * t.sin();
                let x = lambda * t.cos() - d;
                let t_next = t + x.asin();
                // c_{k+1}/c_k = dθ_{k+1}/dθ_k by a derivative of the leaning relation
                let dt_next = 1.0 - lambda * t.sin() / (t_next - t).cos();
                c *= dt_next;
                t = t_next;
            }
            (k, y)
        };
        let inertia = (1.0 + d * d) / 3.0;
        let theta_c = s.asin();
        let (k0, y0) = train(0.0);
        let (kc, yc) = train(theta_c);
        // y sums differ by a convergent series: the far blocks are at θ_∞ in both
        let drop = y0 - yc;
        let r = kc / (kc + 1.0);
        // u_c = (K0 u0 + 2 drop / I)/Kc and u0 = r² u_c
        let u_c = (2.0 * drop / inertia / kc) / (1.0 - r * r * k0 / kc);
        let u0 = r * r * u_c;
        let u = |t: f64| {
            let (k, y) = train(t);
            (k0 * u0 + 2.0 * (y0 - y) / inertia) / k
        };
        let n = 400;
        let hstep = theta_c / n as f64;
        let mut period = 0.0;
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            period += w / u(i as f64 * hstep).sqrt();
        }
        period *= hstep / 3.0;
        let expected = lambda / period;
        let v = speed(Model::Cooperative, d, s);
        assert!(
            (v - expected).abs() <= 1e-9 * expected,
            "{d} {s}: {v} vs {expected}"
        );
        let w = solve(&Model::Cooperative, &Geometry::new(d, s).unwrap()).unwrap();
        let w = w.wave().unwrap();
        assert!((w.omega_after - u0.sqrt()).abs() <= 1e-9 * u0.sqrt());
        assert!((w.omega_before - u_c.sqrt()).abs() <= 1e-9 * u_c.sqrt());
    }
}

/// Single collision model with μ = 0 against a derivation written here: the
/// impact from angular impulse about each block's pivot edge and Newton's
/// restitution at the contact point (a 3×3 linear system built from the contact
/// point's coordinates), the free fall integrated in time (RK4 in SI units,
/// h = 0.08 m, g = 9.81 m/s²), the cycle iterated until it repeats. RK4 with
/// 2·10⁻⁵ s steps is good to ~10⁻⁸, so the check is at 10⁻⁷.
#[test]
fn single_collision_matches_independent_derivation() {
    for &(dh, sh, e) in &[
        (0.12, 0.4, 0.0),
        (0.12, 0.6, 0.5),
        (0.2, 0.5, 0.9),
        (0.1, 0.8, 0.3),
    ] {
        let (h, g, m) = (0.08_f64, 9.81_f64, 0.02_f64);
        let (d, s) = (dh * h, sh * h);
        let inertia = m * (h * h + d * d) / 12.0 + m * (d * d + h * h) / 4.0; // parallel axes
                                                                              // contact point: the striker's top front corner on the target's back face x = s
        let yc = (h * h - s * s).sqrt();
        let contact = [s, yc];
        let pivot_a = [0.0, 0.0];
        let pivot_b = [s + d, 0.0];
        let n = [1.0, 0.0]; // normal, into the target
        let cross = |r: [f64; 2], f: [f64; 2]| r[0] * f[1] - r[1] * f[0]; // counter-clockwise
        let ra = [contact[0] - pivot_a[0], contact[1] - pivot_a[1]];
        let rb = [contact[0] - pivot_b[0], contact[1] - pivot_b[1]];
        // velocity of a point r from a pivot turning counter-clockwise at w: w (−r_y, r_x)
        let vel = |r: [f64; 2], w: f64| [-w * r[1], w * r[0]];
        let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
        // one collision: unknowns (wa, wb, P) with counter-clockwise angular velocities
        let collide = |wa_minus: f64| -> f64 {
            // I (wa − wa⁻) = ra × (−P n);  I wb = rb × (P n);
            // (v_A(C) − v_B(C))·n after = −e (v_A(C) − v_B(C))·n before
            let ka = cross(ra, [-n[0], -n[1]]) / inertia; // wa = wa⁻ + ka P
            let kb = cross(rb, n) / inertia; // wb = kb P
            let vn = |wa: f64, wb: f64| dot(vel(ra, wa), n) - dot(vel(rb, wb), n);
            let before = vn(wa_minus, 0.0);
            // vn is linear: vn(wa⁻ + ka P, kb P) = before + P (vn(ka, 0) + vn(0, kb))
            let slope = vn(ka, 0.0) + vn(0.0, kb);
            let p = (-e * before - before) / slope;
            kb * p
        };
        // clockwise (forward) fall of one block about its front edge, θ from the vertical
        let accel = |t: f64| {
            // centre of mass at (−d/2, h/2) rotated clockwise by t
            let x = -0.5 * d * t.cos() + 0.5 * h * t.sin();
            m * g * x / inertia
        };
        let theta_c = (s / h).asin();
        let rk4 = |t: f64, w: f64, dt: f64| {
            let (k1t, k1w) = (w, accel(t));
            let (k2t, k2w) = (w + 0.5 * dt * k1w, accel(t + 0.5 * dt * k1t));
            let (k3t, k3w) = (w + 0.5 * dt * k2w, accel(t + 0.5 * dt * k2t));
            let (k4t, k4w) = (w + dt * k3w, accel(t + dt * k3t));
            (
                t + dt / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t),
                w + dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w),
            )
        };
        // fall from upright at w0 to θ_c: returns (time, angular velocity at θ_c)
        let fall = |w0: f64| {
            let dt = 2e-5;
            let (mut t, mut w, mut time) = (0.0, w0, 0.0);
            loop {
                assert!(w > 0.0, "stalled");
                let (t1, w1) = rk4(t, w, dt);
                if t1 >= theta_c {
                    // last partial step by bisection on its length
                    let (mut lo, mut hi) = (0.0, dt);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if rk4(t, w, mid).0 < theta_c {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    let (_, wf) = rk4(t, w, hi);
                    return (time + hi, wf);
                }
                t = t1;
                w = w1;
                time += dt;
            }
        };
        // iterate: the striker hits at −w (clockwise = negative counter-clockwise)
        let mut w_before = 3.0 * (g / h).sqrt();
        let mut period = 0.0;
        for _ in 0..200 {
            let w_after = -collide(-w_before);
            let (time, wc) = fall(w_after);
            let converged = (wc - w_before).abs() < 1e-13 * wc;
            w_before = wc;
            period = time;
            if converged {
                break;
            }
        }
        let expected = (s + d) / period / (g * h).sqrt();
        let out = solve(
            &Model::Single { mu: 0.0, e },
            &Geometry::new(dh, sh).unwrap(),
        )
        .unwrap();
        let wave = out.wave().unwrap_or_else(|| panic!("no wave: {out:?}"));
        let v = wave.natural_speed;
        assert!(
            (v - expected).abs() <= 1e-7 * expected,
            "{dh} {sh} {e}: {v} vs {expected}"
        );
        let w_scaled = w_before / (g / h).sqrt();
        assert!((wave.omega_before - w_scaled).abs() <= 1e-7 * w_scaled);
    }
}

/// The smallest spacing with a wave is bracketed by a spacing without and one with.
#[test]
fn smallest_spacing_is_bracketed() {
    let models = [
        Model::Cooperative,
        Model::Extended { mu: 0.15 },
        Model::Single { mu: 0.15, e: 0.62 },
        Model::Single { mu: 0.0, e: 0.0 },
    ];
    for model in models {
        let tol = 1e-7;
        let b = match min_spacing(&model, 0.12, tol) {
            Ok(b) => b,
            Err(err) => {
                // only the cooperative model may have waves at every spacing
                assert_eq!(model, Model::Cooperative, "{err}");
                continue;
            }
        };
        assert!(b.without_wave < b.with_wave && b.with_wave - b.without_wave <= tol);
        let at = |s: f64| solve(&model, &Geometry::new(0.12, s).unwrap()).unwrap();
        assert!(
            matches!(at(b.without_wave), Outcome::NoWave(_)),
            "{model:?}"
        );
        assert!(matches!(at(b.with_wave), Outcome::Wave(_)), "{model:?}");
    }
    // single collision, μ = e = 0: a wave needs gravity to make up the collision
    // loss (θ_c > 2φ, tan φ = d/h) and the struck block to get over the top:
    // ω_after = ω_before/2, so u0 = G/3 with G = (2 m g R / I)(cos φ − cos(θ_c − φ)),
    // and u0 > (2 m g R / I)(1 − cos φ). Solved here by bisection in θ_c.
    let phi = 0.12_f64.atan();
    let ok = |tc: f64| {
        let gain = phi.cos() - (tc - phi).cos();
        gain > 0.0 && gain / 3.0 > 1.0 - phi.cos()
    };
    let (mut lo, mut hi) = (0.0_f64, 1.5_f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if ok(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let expected = hi.sin();
    let b = min_spacing(&Model::Single { mu: 0.0, e: 0.0 }, 0.12, 1e-9).unwrap();
    assert!(
        (b.with_wave - expected).abs() < 1e-8,
        "{} vs {expected}",
        b.with_wave
    );
    assert!(matches!(
        solve(
            &Model::Single { mu: 0.0, e: 0.0 },
            &Geometry::new(0.12, expected - 1e-6).unwrap()
        )
        .unwrap(),
        Outcome::NoWave(NoWave::LeaderStalls { .. })
    ));
}

/// Bad input is an error, not a panic.
#[test]
fn invalid_parameters_are_errors() {
    assert!(Geometry::new(0.0, 0.3).is_err());
    assert!(Geometry::new(f64::NAN, 0.3).is_err());
    assert!(Geometry::new(0.12, 0.0).is_err());
    let g = Geometry::new(0.12, 0.3).unwrap();
    assert!(solve(&Model::Extended { mu: -0.1 }, &g).is_err());
    assert!(solve(&Model::Single { mu: 0.1, e: 1.5 }, &g).is_err());
    assert!(solve(
        &Model::Single {
            mu: f64::INFINITY,
            e: 0.5
        },
        &g
    )
    .is_err());
    assert_eq!(
        solve(&Model::Cooperative, &Geometry::new(0.12, 1.0).unwrap()).unwrap(),
        Outcome::NoWave(NoWave::NoCollision)
    );
}
