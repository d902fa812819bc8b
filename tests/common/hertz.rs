//! An independent oracle: a chain of balls on a line with compliant contacts
//! F = k δ^α, integrated in time with classical RK4 (no code shared with the
//! resolver). Ball i touches ball i+1; optionally the last ball touches a wall.

/// A 1D chain problem: masses, initial velocities (m/s), contact stiffnesses
/// between neighbours (and with the wall, last entry, when `wall`), exponent α.
#[derive(Clone, Debug)]
pub struct Chain {
    pub masses: Vec<f64>,
    pub velocities: Vec<f64>,
    pub stiffness: Vec<f64>,
    pub exponent: f64,
    pub wall: bool,
}

impl Chain {
    pub fn contacts(&self) -> usize {
        self.masses.len() - 1 + usize::from(self.wall)
    }

    /// Compression rate of contact j (positive while approaching).
    fn closing(&self, j: usize, v: &[f64]) -> f64 {
        if j + 1 < self.masses.len() {
            v[j] - v[j + 1]
        } else {
            v[j] // the wall does not move
        }
    }

    fn derivative(&self, delta: &[f64], v: &[f64], d_delta: &mut [f64], d_v: &mut [f64]) {
        let n = self.masses.len();
        d_v.iter_mut().for_each(|a| *a = 0.0);
        for j in 0..self.contacts() {
            d_delta[j] = self.closing(j, v);
            let f = if delta[j] > 0.0 {
                self.stiffness[j] * delta[j].powf(self.exponent)
            } else {
                0.0
            };
            d_v[j] -= f / self.masses[j];
            if j + 1 < n {
                d_v[j + 1] += f / self.masses[j + 1];
            }
        }
    }

    /// Integrates from touching (all δ = 0) until no contact is compressed and
    /// no pair approaches; returns the final velocities.
    pub fn integrate(&self, dt: f64) -> Vec<f64> {
        let n = self.masses.len();
        let m = self.contacts();
        let mut delta = vec![0.0; m];
        let mut v = self.velocities.clone();
        let (mut k1d, mut k2d, mut k3d, mut k4d) =
            (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let (mut k1v, mut k2v, mut k3v, mut k4v) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut td, mut tv) = (vec![0.0; m], vec![0.0; n]);
        for _ in 0..200_000_000u64 {
            let done = (0..m).all(|j| delta[j] <= 0.0 && self.closing(j, &v) <= 0.0);
            if done {
                return v;
            }
            self.derivative(&delta, &v, &mut k1d, &mut k1v);
            for j in 0..m {
                td[j] = delta[j] + 0.5 * dt * k1d[j];
            }
            for i in 0..n {
                tv[i] = v[i] + 0.5 * dt * k1v[i];
            }
            self.derivative(&td, &tv, &mut k2d, &mut k2v);
            for j in 0..m {
                td[j] = delta[j] + 0.5 * dt * k2d[j];
            }
            for i in 0..n {
                tv[i] = v[i] + 0.5 * dt * k2v[i];
            }
            self.derivative(&td, &tv, &mut k3d, &mut k3v);
            for j in 0..m {
                td[j] = delta[j] + dt * k3d[j];
            }
            for i in 0..n {
                tv[i] = v[i] + dt * k3v[i];
            }
            self.derivative(&td, &tv, &mut k4d, &mut k4v);
            for j in 0..m {
                delta[j] += dt / 6.0 * (k1d[j] + 2.0 * k2d[j] + 2.0 * k3d[j] + k4d[j]);
            }
            for i in 0..n {
                v[i] += dt / 6.0 * (k1v[i] + 2.0 * k2v[i] + 2.0 * k3v[i] + k4v[i]);
            }
        }
        panic!("Hertz chain did not separate");
    }

    /// Time step resolving the shortest two-body contact duration
    /// (Hertz: t_c ≈ 3.2 (m_eff² / (k² v))^(1/5) for α = 1.5; similar for α = 1).
    pub fn time_step(&self, steps_per_contact: f64) -> f64 {
        let v = self
            .velocities
            .iter()
            .fold(0.0f64, |a, b| a.max(b.abs()))
            .max(1e-9);
        let mut shortest = f64::INFINITY;
        for j in 0..self.contacts() {
            let m1 = self.masses[j];
            let meff = if j + 1 < self.masses.len() {
                m1 * self.masses[j + 1] / (m1 + self.masses[j + 1])
            } else {
                m1
            };
            let a = self.exponent;
            // δ_max from ½ m v² = k δ^(α+1)/(α+1); t_c ~ 2.9 δ_max / v
            let dmax = (0.5 * meff * v * v * (a + 1.0) / self.stiffness[j]).powf(1.0 / (a + 1.0));
            shortest = shortest.min(2.9 * dmax / v);
        }
        shortest / steps_per_contact
    }
}
