//! An independent oracle for e = 1, μ = 0: the compliant model F = k δ^α at
//! every contact, geometry frozen (as the LZB model assumes), integrated in
//! time with classical RK4. It builds its own contact Jacobians from the
//! public input data and shares no code with the resolver.

use topple::impact::{Body, Contact};

struct Arm {
    a: Option<usize>,
    b: Option<usize>,
    n: [f64; 2],
    ra: [f64; 2],
    rb: [f64; 2],
    k: f64,
    alpha: f64,
}

fn cross(r: [f64; 2], v: [f64; 2]) -> f64 {
    r[0] * v[1] - r[1] * v[0]
}

/// Final velocities `[vx, vy, ω]` of every body after the compliant impact.
pub fn integrate(bodies: &[Body], contacts: &[Contact], steps_per_contact: f64) -> Vec<[f64; 3]> {
    let free = |i: Option<usize>| i.filter(|&i| !bodies[i].fixed);
    let arms: Vec<Arm> = contacts
        .iter()
        .map(|c| {
            let r = |i: Option<usize>| {
                i.map(|i| {
                    [
                        c.point[0] - bodies[i].position[0],
                        c.point[1] - bodies[i].position[1],
                    ]
                })
                .unwrap_or([0.0, 0.0])
            };
            Arm {
                a: free(c.bodies[0]),
                b: free(c.bodies[1]),
                n: c.normal,
                ra: r(c.bodies[0]),
                rb: r(c.bodies[1]),
                k: c.material.stiffness,
                alpha: c.material.exponent,
            }
        })
        .collect();
    assert!(contacts
        .iter()
        .all(|c| c.material.restitution == 1.0 && c.material.friction == 0.0));

    let nb = bodies.len();
    let inv = |i: usize| -> (f64, f64) {
        if bodies[i].fixed {
            (0.0, 0.0)
        } else {
            (1.0 / bodies[i].mass, 1.0 / bodies[i].inertia)
        }
    };
    // compression rate −δ̇ = −n·(v_b + ω_b × r_b − v_a − ω_a × r_a)
    let closing = |arm: &Arm, v: &[[f64; 3]]| -> f64 {
        let point = |i: Option<usize>, r: [f64; 2]| match i {
            Some(i) => [v[i][0] - v[i][2] * r[1], v[i][1] + v[i][2] * r[0]],
            None => [0.0, 0.0],
        };
        let (pa, pb) = (point(arm.a, arm.ra), point(arm.b, arm.rb));
        -(arm.n[0] * (pb[0] - pa[0]) + arm.n[1] * (pb[1] - pa[1]))
    };
    let deriv = |delta: &[f64], v: &[[f64; 3]], dd: &mut [f64], dv: &mut [[f64; 3]]| {
        dv.iter_mut().for_each(|x| *x = [0.0; 3]);
        for (j, arm) in arms.iter().enumerate() {
            dd[j] = closing(arm, v);
            let f = if delta[j] > 0.0 {
                arm.k * delta[j].powf(arm.alpha)
            } else {
                0.0
            };
            if let Some(b) = arm.b {
                let (im, ii) = inv(b);
                dv[b][0] += f * arm.n[0] * im;
                dv[b][1] += f * arm.n[1] * im;
                dv[b][2] += f * cross(arm.rb, arm.n) * ii;
            }
            if let Some(a) = arm.a {
                let (im, ii) = inv(a);
                dv[a][0] -= f * arm.n[0] * im;
                dv[a][1] -= f * arm.n[1] * im;
                dv[a][2] -= f * cross(arm.ra, arm.n) * ii;
            }
        }
    };

    let mut v: Vec<[f64; 3]> = bodies
        .iter()
        .map(|b| [b.velocity[0], b.velocity[1], b.angular_velocity])
        .collect();
    // time step from the shortest two-body contact duration
    let speed = arms
        .iter()
        .map(|a| closing(a, &v).abs())
        .fold(1e-12, f64::max);
    let mut shortest = f64::INFINITY;
    for arm in &arms {
        let mut w = 0.0;
        if let Some(b) = arm.b {
            let (im, ii) = inv(b);
            w += im + cross(arm.rb, arm.n).powi(2) * ii;
        }
        if let Some(a) = arm.a {
            let (im, ii) = inv(a);
            w += im + cross(arm.ra, arm.n).powi(2) * ii;
        }
        let dmax =
            (0.5 / w * speed * speed * (arm.alpha + 1.0) / arm.k).powf(1.0 / (arm.alpha + 1.0));
        shortest = shortest.min(2.9 * dmax / speed);
    }
    let dt = shortest / steps_per_contact;

    let m = arms.len();
    let mut delta = vec![0.0; m];
    let zero3 = vec![[0.0; 3]; nb];
    let (mut k1d, mut k2d, mut k3d, mut k4d) =
        (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let (mut k1v, mut k2v, mut k3v, mut k4v) =
        (zero3.clone(), zero3.clone(), zero3.clone(), zero3.clone());
    let (mut td, mut tv) = (vec![0.0; m], zero3.clone());
    for _ in 0..500_000_000u64 {
        let done = arms
            .iter()
            .enumerate()
            .all(|(j, arm)| delta[j] <= 0.0 && closing(arm, &v) <= 0.0);
        if done {
            return v;
        }
        deriv(&delta, &v, &mut k1d, &mut k1v);
        for j in 0..m {
            td[j] = delta[j] + 0.5 * dt * k1d[j];
        }
        for i in 0..nb {
            for c in 0..3 {
                tv[i][c] = v[i][c] + 0.5 * dt * k1v[i][c];
            }
        }
        deriv(&td, &tv, &mut k2d, &mut k2v);
        for j in 0..m {
            td[j] = delta[j] + 0.5 * dt * k2d[j];
        }
        for i in 0..nb {
            for c in 0..3 {
                tv[i][c] = v[i][c] + 0.5 * dt * k2v[i][c];
            }
        }
        deriv(&td, &tv, &mut k3d, &mut k3v);
        for j in 0..m {
            td[j] = delta[j] + dt * k3d[j];
        }
        for i in 0..nb {
            for c in 0..3 {
                tv[i][c] = v[i][c] + dt * k3v[i][c];
            }
        }
        deriv(&td, &tv, &mut k4d, &mut k4v);
        for j in 0..m {
            delta[j] += dt / 6.0 * (k1d[j] + 2.0 * k2d[j] + 2.0 * k3d[j] + k4d[j]);
        }
        for i in 0..nb {
            for c in 0..3 {
                v[i][c] += dt / 6.0 * (k1v[i][c] + 2.0 * k2v[i][c] + 2.0 * k3v[i][c] + k4v[i][c]);
            }
        }
    }
    panic!("compliant impact did not end");
}
