//! An independent implementation, for tests only, of the cooperative group
//! model (Stronge & Shu 1988; van Leeuwen 2010) and its extension with friction
//! between blocks, following reference/theory.md. Not shared with the crate's
//! `theory` module on purpose: it is the oracle the engine is checked against.

/// Natural speed v/√(gh) of the (extended, μ > 0) cooperative group model for
/// blocks of height h, thickness d at gap s, friction μ between blocks.
pub fn cooperative_speed(h: f64, d: f64, s: f64, mu: f64) -> f64 {
    let g = 9.81;
    let lam = s + d;
    let ntrain = 300;
    let inertia = (h * h + d * d) / 3.0; // per unit mass, about the edge
    let r = 0.5 * (h * h + d * d).sqrt();
    let phi = (d / h).atan();
    // train angles θ_k, c_k and ρ_k for leader angle θ0
    let train = |th0: f64, th: &mut Vec<f64>, c: &mut Vec<f64>, rho: &mut Vec<f64>| {
        th.clear();
        c.clear();
        rho.clear();
        th.push(th0);
        c.push(1.0);
        rho.push(1.0);
        for k in 0..ntrain {
            let tk = th[k];
            let x = ((lam * tk.cos() - d) / h).clamp(-1.0, 1.0);
            let tn = tk + x.asin();
            let gk = 1.0 - (lam / h) * tk.sin() / (tn - tk).cos();
            let al = h * (tn - tk).cos() - lam * tk.sin() - mu * d;
            let be = h * (tn - tk).cos() + mu * h * (tn - tk).sin();
            th.push(tn);
            c.push(c[k] * gk);
            rho.push(rho[k] * al / be);
        }
    };
    let (mut th, mut c, mut rho) = (Vec::new(), Vec::new(), Vec::new());
    let (mut thp, mut cp, mut rhop) = (Vec::new(), Vec::new(), Vec::new());
    let (mut thm, mut cm, mut rhom) = (Vec::new(), Vec::new(), Vec::new());
    // coefficients of θ̈0 = (A − u B)/C, u = θ̇0²
    let mut coeffs = |th0: f64| -> (f64, f64, f64) {
        let eps = 1e-6;
        train(th0, &mut th, &mut c, &mut rho);
        train(th0 + eps, &mut thp, &mut cp, &mut rhop);
        train(th0 - eps, &mut thm, &mut cm, &mut rhom);
        let (mut a, mut b, mut cc) = (0.0, 0.0, 0.0);
        for k in 0..=ntrain {
            let tau = g * r * (th[k] - phi).sin();
            let dc = (cp[k] - cm[k]) / (2.0 * eps);
            a += rho[k] * tau / inertia;
            b += rho[k] * dc;
            cc += rho[k] * c[k];
        }
        (a, b, cc)
    };
    let thc = (s / h).asin();
    // tabulate on a grid
    let n = 400;
    let dth = thc / n as f64;
    let mut tab = Vec::with_capacity(2 * n + 1);
    for i in 0..=2 * n {
        tab.push(coeffs(0.5 * dth * i as f64));
    }
    let f = |j: usize, u: f64| {
        let (a, b, cc) = tab[j];
        2.0 * (a - u * b) / cc
    };
    // RK4 in θ with half steps from the table
    let integrate = |u0: f64, us: &mut Vec<f64>| {
        us.clear();
        let mut u = u0;
        us.push(u);
        for i in 0..n {
            let j = 2 * i;
            let k1 = f(j, u);
            let k2 = f(j + 1, u + 0.5 * dth * k1);
            let k3 = f(j + 1, u + 0.5 * dth * k2);
            let k4 = f(j + 2, u + dth * k3);
            u += dth / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            us.push(u);
        }
    };
    let mut us = Vec::new();
    integrate(0.0, &mut us);
    let b0 = *us.last().unwrap();
    integrate(1.0, &mut us);
    let a0 = *us.last().unwrap() - b0;
    // collision at θc with the train at θc
    train(thc, &mut th, &mut c, &mut rho);
    let s_rc: f64 = (0..=ntrain).map(|k| rho[k] * c[k]).sum();
    let jm1 = (h * thc.cos() - mu * d) / (h * thc.cos() + mu * h * thc.sin()) * s_rc;
    let ratio = jm1 / (jm1 + 1.0);
    let u_star = ratio * ratio * b0 / (1.0 - ratio * ratio * a0);
    integrate(u_star, &mut us);
    // period T = ∫ dθ / √u, Simpson
    let mut t = 0.0;
    for (i, u) in us.iter().enumerate().take(n + 1) {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        t += w / u.sqrt();
    }
    t *= dth / 3.0;
    lam / t / (g * h).sqrt()
}
